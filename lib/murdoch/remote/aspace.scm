;;;; Address spaces: identity, peers and live membership (thesis §3.3.2).
;;;; This process joins its lab as one (join-lab!) and learns the others
;;;; from the lab file, their hellos and their beacons.


(define-record-type aspace
  (make-aspace uid host port)
  ;;> True for an address space, as uid->aspace and local-aspace answer.
  aspace?
  ;;> The uid of an address space, a symbol.
  (uid aspace-uid)
  (host aspace-host)
  (port aspace-port))

;; The node's membership part: this process as an address space of its
;; lab, made once by join-lab!.
(define-record-type membership
  (make-membership started-at environment decode timeout peers unreachable
                   peers-lock)
  membership?
  (started-at membership-started-at)    ; (utc-seconds) at join-lab!
  (local membership-local membership-local-set!)
  (environment membership-environment)  ; received code runs in it
  (decode membership-decode)            ; received code is rebuilt by it
  (timeout membership-timeout)          ; remote-apply's default
  (peers membership-peers)              ; uid -> aspace, from lab and hellos
  (unreachable membership-unreachable)  ; uid -> #t: out of the live set
  (peers-lock membership-peers-lock)    ; over peers, unreachable and live
  (live membership-live membership-live-set!)) ; the live set, #f once changed

;; Read by every call served: no procedure, nor or (docs/speed.md).
(define-syntax joined
  (syntax-rules ()
    ((_) (if (and *node* (node-membership *node*))
             (node-membership *node*)
             (error "this process has not joined a lab")))))

(define (with-peers thunk)
  (with-lock (membership-peers-lock (joined)) thunk))

;; Peers or who answers changed: the live set is remade when asked for (under the lock).
(define (peers-changed! m) (membership-live-set! m #f))

;;> The local address space.
(define (local-aspace) (membership-local (joined)))

;;> Makes \var{port} the local address space's: a guest's, listening on port 0.
(define (local-aspace-port-set! port)
  (let ((local (local-aspace)))
    (membership-local-set! (joined)
                           (make-aspace (aspace-uid local) (aspace-host local) port))
    (learn-aspace! (local-aspace))))

;;> The (utc-seconds) at which this address space joined its lab.
(define (aspace-started-at) (membership-started-at (joined)))

;;> The uid of the local address space.
(define (local-aspace-uid) (aspace-uid (local-aspace)))

;;> The address space named \var{uid}.
(define (uid->aspace uid)
  (or (known-aspace (joined) uid)
      (error "no address space of this uid is known" uid)))

;; No wind around the lock: nothing under it raises (docs/speed.md).
(define (known-aspace m uid)
  (lock! (membership-peers-lock m))
  (unlocked (membership-peers-lock m)
            (cell-value (hash-table-cell (membership-peers m) uid #f) #f)))

;;> The uids of every address space known here (the thesis's *uids*).
(define (known-uids)
  (with-peers (lambda () (hash-table-keys (membership-peers (joined))))))

(define (learn-aspace! a)
  (with-peers
    (lambda ()
      (hash-table-set! (membership-peers (joined)) (aspace-uid a) a)
      (peers-changed! (joined)))))

;;; Live membership
;; One that fails to connect, loses its connection or does not answer in
;; time leaves the live set, for a prober to try every second; a newcomer
;; is learned from its hello.

(define (note-unreachable! uid)
  (if (not (eq? uid (local-aspace-uid)))
      (with-peers
        (lambda ()
          (hash-table-set! (membership-unreachable (joined)) uid #t)
          (peers-changed! (joined))))))

;; uid answers again, or a beacon of it came.
(define (note-reachable! uid)
  (with-peers
    (lambda ()
      (hash-table-delete! (membership-unreachable (joined)) uid)
      (peers-changed! (joined)))))

(define (unreachable-uids)
  (with-peers (lambda () (hash-table-keys (membership-unreachable (joined))))))

;;> The uids of the address spaces that answer: the broadcast set.
(define (live-uids) (map aspace-uid (live-aspaces)))

;;> The address spaces that answer, this one among them (kept: docs/speed.md).
(define (live-aspaces)
  (let ((m (joined)))
    (or (membership-live m)
        (with-peers (lambda () (live-now! m))))))

(define (live-now! m)
  (let ((live (remove (lambda (a) (hash-table-ref/default (membership-unreachable m)
                                                          (aspace-uid a) #f))
                      (hash-table-values (membership-peers m)))))
    (membership-live-set! m live)
    live))

;;> The live address space of \var{uid}, or #f.
(define (live-aspace uid)
  (find (lambda (a) (eq? (aspace-uid a) uid)) (live-aspaces)))

;;; The timeout

;;> A per-call override: (parameterize ((remote-timeout 1)) ...).
(define remote-timeout (make-parameter #f))
(sandbox-parameter! remote-timeout)

(define (current-timeout) (timeout-or-lab (remote-timeout)))

(define (timeout-or-lab t) (if t t (membership-timeout (joined))))

;;; The environment received code runs in

;;> The environment received code runs in: R7RS base, Murdoch's API and the
;;> lab's code files, without file, process, load or eval primitives.
(define (lab-environment) (membership-environment (joined)))

;; The value received code stands for, rebuilt in place: code fresh from a frame.
(define (decode-value code) ((membership-decode (joined)) code))

(define (describe-procedure proc)
  (let ((encoded (guard (e (#t #f)) (encode proc (lab-environment) "procedure"))))
    (cond ((and (vector? encoded) (eq? (vector-ref encoded 0) 'murdoch:global))
           (vector-ref encoded 1))
          ((and (vector? encoded) (eq? (vector-ref encoded 0) 'murdoch:closure))
           (vector-ref encoded 1))
          (else proc))))

;;> Makes this process the address space \var{uid} of its lab, on
;;> \var{port}, receiving code into \var{environment} via \var{decode}.
(define (join-lab! uid host port environment decode)
  (let ((m (make-membership (utc-seconds) environment decode (call-timeout)
                            (make-hash-table eq?) (make-hash-table eq?)
                            (make-mutex 'peers))))
    (membership-live-set! m #f)
    (membership-local-set! m (make-aspace uid host port))
    (node-membership-set! (this-node) m))
  (for-each (lambda (a)
              (learn-aspace! (make-aspace (lab-aspace-uid a) (lab-aspace-host a)
                                          (lab-aspace-port a))))
            (lab-aspaces (current-lab)))
  (learn-aspace! (local-aspace))
  (local-aspace))
