;;;; The node, part of (murdoch lab): this process as an address space of
;;;; its lab, one record whose parts the layers fill as it starts
;;;; (docs/architecture.md, "How an address space starts").

(define-record-type node
  (make-node lab role wire limits sandbox membership connections server group
             subscriber monitors teams poses runs posed line looking offering handing)
  node?
  (lab node-lab)                        ; read once; its settings by setting
  (role node-role)                      ; aspace, or repl: a person waits at it
  (wire node-wire node-wire-set!)       ; wire/frame.scm: the key, frame limits
  (limits node-limits node-limits-set!) ; code/sendable.scm: values sent
  (sandbox node-sandbox node-sandbox-set!) ; code/sandbox.scm: max-alloc, ports
  (membership node-membership node-membership-set!) ; remote/aspace.scm
  (connections node-connections node-connections-set!) ; remote/connection.scm
  (server node-server node-server-set!) ; remote/serve.scm
  (group node-group node-group-set!)    ; remote/group.scm, #f under broadcast
  (subscriber node-subscriber node-subscriber-set!) ; pubsub/messaging.scm
  (monitors node-monitors node-monitors-set!) ; pubsub/monitor.scm: thresholds
  ;; The task layer's parts, made by its open-tasks! (task/parts.scm):
  (teams node-teams node-teams-set!)    ; task/team.scm: teams held here
  (poses node-poses node-poses-set!)    ; task/pose-task.scm: negotiating
  (runs node-runs node-runs-set!)       ; task/running.scm: components run here
  (posed node-posed node-posed-set!)    ; task/record.scm: tasks started here
  (line node-line node-line-set!)       ; task/rank.scm: waiting, known posers
  (looking node-looking node-looking-set!) ; task/waiting.scm: the poser's look
  (offering node-offering node-offering-set!) ; task/offers.scm: offer rounds
  (handing node-handing node-handing-set!)) ; task/detached.scm: tasks handed

;; Global: a process is one address space of one lab.  The layers' hot
;; paths read their part straight from it (docs/speed.md).
(define *node* #f)

;;> Makes this process a node of \var{lab}, its parts yet to be filled;
;;> \var{role} is \scheme{repl} for a person's REPL, else \scheme{aspace}.
(define (open-node! lab . role)
  (set! *node* (make-node lab (if (pair? role) (car role) 'aspace)
                         #f #f #f #f #f #f #f #f #f #f #f #f #f #f #f #f #f))
  *node*)

;;> This process's node, for a layer to fill its part.
(define (this-node)
  (or *node* (error "this process has not joined a lab")))

;;> The lab this address space belongs to.
(define (current-lab) (node-lab (this-node)))

;;> The value of setting \var{key} of this address space's lab.
(define (setting key) (lab-setting (current-lab) key))

;;> Seconds a call waits for its answer unless told otherwise: at a REPL,
;;> where a person waits and Ctrl-C gives a call up, repl-timeout.
(define (call-timeout)
  (setting (if (eq? (node-role (this-node)) 'repl) 'repl-timeout 'timeout)))
