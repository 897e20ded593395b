;;;; Tasks handed to the lab: a detached task's coordinator and its standby.
;;
;; start-task and start-steps with 'detach #t hand the task to the lab,
;; which keeps it on two of its members, chosen as it chooses robots:
;;
;;  1. The poser asks the address spaces with the coordinator capability
;;     (the workstations, by default) for their load, and hands the task
;;     to the least loaded one other than itself, its coordinator.  It
;;     answers the task's id, and may leave.
;;  2. The coordinator starts the task as start-task would, and does for
;;     it all a poser does: heartbeats, reassignments, its place in line.
;;     It chooses a standby the same way, on another member, and sends it
;;     a copy of the task's record whenever it changes, and every period,
;;     and of a step's team at each arrival or letter, before the member
;;     that made the call hears back (team.scm).
;;  3. Never two coordinators.  The standby pings the coordinator every
;;     heartbeat period.  The coordinator acts for the task (heartbeats,
;;     starts, negotiations) only while the pings arrive: silent for two
;;     periods, it lets the task go.  The standby takes over when no ping
;;     has been answered for four periods, or one period after it finds
;;     the coordinator's process gone (its port refuses, or its new
;;     process holds no such task).  docs/tasks.md gives the argument.
;;  4. Taking over, the standby asks the lab which of the task's
;;     components run or ended where, adopts each where it is, re-runs the
;;     negotiation of a task that had not started, with its rank, and
;;     chooses a new standby.  The members of a step's team find its
;;     coordinator there by the step's id.  A coordinator that let the
;;     task go because its standby fell silent takes it back the same way
;;     once it finds the standby's process gone, and drops it if the
;;     standby took over.
;;  5. Any peer finds the task by its id through the lab-tasks subject,
;;     which the members holding a task subscribe to.  A finished task's
;;     results are kept for the lab's keep-results seconds.
;;
;; Its components wait detached-patience times longer for their
;; coordinator than a poser's, so a takeover comes before they stop.

(define detached-patience 4)

;; Let go after let-go-periods without the standby's pings; take over
;; after take-over-periods unanswered: the no-ghost rule's settings, with
;; the coordinator in the robot's place (docs/tasks.md).
(define (let-go-periods) (orphan-periods))
(define (take-over-periods) (lost-periods))

;; What a coordinator and its standby each keep of a detached task.
(define-record-type handed
  (make-handed id kind args poser)
  handed?
  (id handed-id)
  (kind handed-kind)                    ; task or steps
  (args handed-args)                    ; start-task's, or start-steps's
  (poser handed-poser)
  (role handed-role handed-role-set!)   ; coordinator, standby or let-go
  (partner handed-partner handed-partner-set!)   ; the other's uid, or #f
  (epoch handed-epoch handed-epoch-set!)         ; 1, and 1 more a takeover
  (task handed-task handed-task-set!)            ; the coordinator's record
  (copy handed-copy handed-copy-set!)            ; as last sent or received
  (heard handed-heard handed-heard-set!)         ; monotonic: the partner, last
  (teams handed-teams handed-teams-set!)         ; ((TEAM-ID STATE) ...), its steps'
  (took-over handed-took-over handed-took-over-set!)) ; utc-seconds, or #f

;; The copy of a task's record that travels to the standby: (STATE STATUS
;; RESULTS TURN ENDED), RESULTS #f until it ends, TURN what the task's
;; rank and deadline are made of (task-turn-copy), ENDED the utc-seconds
;; it ended, or #f.
(define (copy-state c) (car c))
(define (copy-status c) (cadr c))
(define (copy-results c) (list-ref c 2))
(define (copy-turn c) (list-ref c 3))
(define (copy-ended c) (list-ref c 4))

;; Global: the calls of peers find them by name.
(define *handed* '())
(define *handed-lock* (make-mutex 'handed))

(define (handed-by-id id)
  (with-lock *handed-lock*
    (lambda () (find (lambda (h) (eq? (handed-id h) id)) *handed*))))

(define (hold-handed! h)
  (with-lock *handed-lock*
    (lambda ()
      (set! *handed* (cons h (remove (lambda (x) (eq? (handed-id x) (handed-id h)))
                                     *handed*)))
      (subscribe 'lab-tasks))))

(define (drop-handed! h)
  (with-lock *handed-lock*
    (lambda ()
      (set! *handed* (remove (lambda (x) (eq? x h)) *handed*))
      (if (null? *handed*) (unsubscribe 'lab-tasks)))))

(define (period) (setting 'heartbeat))

;;; The poser's side

;;> Poses a task as start-task in (murdoch task life-cycle) does; with
;;> the keyword \scheme{detach} #t among its options, hands it to the lab
;;> instead and answers its id: see lib/murdoch/task/detached.scm.
(define (start-task task-name num-robots capability-list metrics procs . options)
  (let* ((lists (take-while list? options))
         (keywords (drop options (length lists)))
         (args (append (list task-name num-robots capability-list metrics procs) lists
                       (without-detach keywords))))
    (if (detach? keywords)
        (hand-to-lab 'task args)
        (apply start-here args))))

;;> Starts a task of steps as start-steps in (murdoch task life-cycle)
;;> does; with \scheme{detach} #t after the steps, hands it to the lab and
;;> answers its id.
(define (start-steps task-name . steps+options)
  (let* ((steps (take-while step? steps+options))
         (keywords (drop steps+options (length steps))))
    (if (detach? keywords)
        (hand-to-lab 'steps (list task-name (map step-parts steps)
                                  (without-detach keywords)))
        (apply start-steps-here task-name steps+options))))

;; Whether keywords, start-task's, say detach #t.
(define (detach? keywords)
  (let ((detach (member 'detach keywords)))
    (and detach (pair? (cdr detach))
         (or (boolean? (cadr detach))
             (error "start-task: detach is #t or #f" (cadr detach)))
         (cadr detach))))

(define (without-detach keywords)
  (let loop ((kv keywords))
    (cond ((or (null? kv) (null? (cdr kv))) kv)
          ((eq? (car kv) 'detach) (cddr kv))
          (else (cons (car kv) (cons (cadr kv) (loop (cddr kv))))))))

;; Starts here the task of kind (task or steps) that args describe.
(define (start-kind kind args)
  (if (eq? kind 'steps)
      (apply start-steps-here (car args)
             (append (map (lambda (parts) (apply task-step parts)) (cadr args))
                     (car (cddr args))))
      (apply start-here args)))

(define (hand-to-lab kind args)
  (let ((poser (local-aspace-uid)))
    (let try ((candidates (coordinator-candidates (list poser))))
      (if (null? candidates)
          (error (string-append
                  "start-task: no other address space of the lab can coordinate a"
                  " detached task: none with the coordinator capability answers")))
      (let ((uid (car candidates)))
        (or (guard (e ((remote-raised-error? e) (raise e))
                      ((remote-error? e)
                       (log-warn "handing a task to " uid ": " (error-message e))
                       #f))
              (remote-apply (uid->aspace uid) coordinate-task! kind args poser))
            (try (cdr candidates)))))))

;; The uids that may coordinate a detached task, those in excluded left
;; out, least loaded first (the load metric).
(define (coordinator-candidates excluded)
  (map car
       (list-sort (lambda (a b)
                    (or (< (cadr a) (cadr b))
                        (and (= (cadr a) (cadr b))
                             (string<? (symbol->string (car a))
                                       (symbol->string (car b))))))
                  (filter-map (lambda (answer)
                                (and (not (memq (car answer) excluded))
                                     (string->number (cadr answer))
                                     (list (car answer) (string->number (cadr answer)))))
                              (guard (e (#t '()))
                                (parameterize ((remote-timeout (max 1 (* 2 (period)))))
                                  (request 'coordinator get-system-load)))))))

;;; The coordinator

;;> What the poser of a detached task calls at the coordinator the lab
;;> chose: starts the task of \var{kind} that \var{args} describe here
;;> (see start-kind); answers its id.
(define (coordinate-task! kind args poser)
  (let* ((id (fresh-id (car args)))
         (h (make-handed id kind args poser)))
    (handed-role-set! h 'coordinator)
    (handed-partner-set! h #f)
    (handed-epoch-set! h 1)
    (handed-task-set! h #f)
    (handed-copy-set! h (list 'negotiating '() #f #f #f))
    (handed-heard-set! h (monotonic-seconds))
    (handed-teams-set! h '())
    (handed-took-over-set! h #f)
    ;; Held before it starts, so that its steps' teams are kept from the first.
    (hold-handed! h)
    (let ((t (undo-on-raise
              (lambda () (drop-handed! h))
              (lambda ()
                (parameterize ((heartbeat-patience detached-patience)
                               (task-id-maker (lambda (name) id))
                               (team-keeper keep-team))
                  (start-kind kind args))))))
      (handed-task-set! h t)
      (handed-copy-set! h (list 'negotiating '() #f (task-turn-copy t) #f))
      (coordinate! h)
      id)))

;; A task id no peer of the lab knows, lab-task-key's: a coordinator
;; started again counts its ids from 1 again, and the lab keeps results,
;; and robots remember the components that ended, by id.
(define (fresh-id name)
  (let ((id (lab-task-key name)))
    (if (or (holder-of id) (pair? (components-of id))
            (pair? (components-of (step-task-id id 1))))
        (fresh-id name)
        id)))

;; Starts h's coordinator threads: the standby's copy, the task's end.
(define (coordinate! h)
  (let ((t (handed-task h)) (epoch (handed-epoch h)))
    (if t
        (thread-start!
         (make-logged-thread
          (lambda ()
            (let ((results (task-wait t)))
              (when (and (eq? (handed-role h) 'coordinator) (= epoch (handed-epoch h)))
                (handed-copy-set! h (list (task-state t) (task-status t) results
                                          (task-turn-copy t) (utc-seconds)))
                (progress (handed-id h) ": ended; results kept for "
                          (setting 'keep-results) " s"))))
          'coordinator)))
    (thread-start! (make-logged-thread (lambda () (keep-watch h epoch)) 'coordinator))))

;; Every quarter period: let go when the standby's pings stop; send it a
;; copy when the record changes, and every period.
(define (keep-watch h epoch)
  (let loop ((sent-at 0) (sent #f))
    (thread-sleep! (/ (period) 4))
    (when (and (eq? (handed-role h) 'coordinator) (= epoch (handed-epoch h)))
      (let ((copy (current-copy h)))
        (handed-copy-set! h copy)
        (cond
         ((kept-enough? copy) (drop-handed! h))
         ;; Ended, and the standby has the copy: nothing more to say.
         ((and (copy-results copy) (equal? copy sent)) (loop sent-at sent))
         ((and (handed-partner h)
               (> (- (monotonic-seconds) (handed-heard h)) (* (let-go-periods) (period))))
          (let-go! h))
         ((or (not (equal? copy sent)) (> (- (monotonic-seconds) sent-at) (period)))
          (loop (monotonic-seconds)
                (and (if (handed-partner h) (send-copy! h copy) (choose-standby! h))
                     copy)))
         (else (loop sent-at sent)))))))

(define (current-copy h)
  (let ((t (handed-task h)) (old (handed-copy h)))
    (if (or (not t) (copy-results old))
        old
        (list (state-now t) (task-status t) #f (task-turn-copy t) #f))))

;; t's state; a task of steps that is not over is in its step's, and
;; running between two steps.
(define (state-now t)
  (let ((steps (task-steps t)))
    (if (and (pair? steps) (eq? (task-state t) 'negotiating))
        (let ((state (task-state (last steps))))
          (if (memq state '(negotiating waiting holding running)) state 'running))
        (task-state t))))

(define (kept-enough? copy)
  (and (copy-ended copy)
       (> (- (utc-seconds) (copy-ended copy)) (setting 'keep-results))))

(define (send-copy! h copy)
  (let ((uid (handed-partner h)))
    (guard (e ((and (remote-error? e) (not (remote-raised-error? e)))
               (if (gone-by? e uid) (lost-standby! h uid))
               #f))
      (or (parameterize ((remote-timeout (period)))
            (remote-apply (uid->aspace uid) receive-copy (handed-id h)
                          (handed-epoch h) copy))
          (begin (lost-standby! h uid) #f)))))

(define (lost-standby! h uid)
  (log-warn "task " (handed-id h) ": its standby " uid " is gone; choosing another")
  (handed-partner-set! h #f)
  (choose-standby! h))

;; Asks the least loaded other member to stand by, the poser left out
;; while another will do.
(define (choose-standby! h)
  (let* ((me (local-aspace-uid))
         (all (coordinator-candidates (list me)))
         (others (remove (lambda (u) (eq? u (handed-poser h))) all)))
    (let try ((candidates (if (pair? others) others all)))
      (and (pair? candidates)
        (let ((uid (car candidates)))
          (if (guard (e (#t #f))
                (parameterize ((remote-timeout (period)))
                  (remote-apply (uid->aspace uid) become-standby! (handed-id h)
                                (handed-kind h) (handed-args h) (handed-poser h)
                                (handed-epoch h) (handed-copy h) (handed-teams h) me)))
              (begin
                (handed-heard-set! h (monotonic-seconds))
                (handed-partner-set! h uid)
                (log-note "task " (handed-id h) ": " uid " stands by")
                #t)
              (try (cdr candidates))))))))

;;> What the standby of task \var{id} calls at its coordinator every
;;> period: answers whether it coordinates the task at \var{epoch}.
(define (coordinator-ping id epoch)
  (let ((h (handed-by-id id)))
    (and h (eq? (handed-role h) 'coordinator) (= (handed-epoch h) epoch)
         (begin (handed-heard-set! h (monotonic-seconds)) #t))))

;; The coordinator stops acting for h: its standby is silent, and may be
;; about to take over.  It takes the task back only once it finds the
;; standby's process gone; it drops it when the standby took over.
(define (let-go! h)
  (let ((uid (handed-partner h)) (t (handed-task h)))
    (handed-role-set! h 'let-go)
    (if t (let-task-go! t))
    (log-warn "task " (handed-id h) ": its standby " uid " is silent; letting it go;"
              " its last heartbeat went at " (and t (task-acted t)))
    (thread-start!
     (make-logged-thread
      (lambda ()
        (let probe ()
          (thread-sleep! (period))
          (let ((there (guard (e (#t (if (gone-by? e uid) 'gone 'silent)))
                         (parameterize ((remote-timeout (period)))
                           (remote-apply (uid->aspace uid) handed-role-of
                                         (handed-id h))))))
            (cond ((memq there '(gone #f let-go))
                   (log-note "task " (handed-id h) ": " uid " is gone; taking it back")
                   (take-over! h (list uid)))
                  ((eq? there 'coordinator)
                   (log-note "task " (handed-id h) ": " uid " took it over")
                   (drop-handed! h))
                  (else (probe))))))
      'let-go))))

;;> The role this address space has for task \var{id}: coordinator,
;;> standby or let-go, or #f.
(define (handed-role-of id)
  (let ((h (handed-by-id id)))
    (and h (handed-role h))))

;; Whether e, what a call to uid raised, says that uid's process is gone:
;; the call found no connection, and its port refuses one.  A partition
;; answers nothing, or says that there is no route.
(define (gone-by? e uid)
  (and (remote-unreachable-error? e) (process-gone? uid)))

(define (process-gone? uid)
  (let* ((a (uid->aspace uid))
         (io (open-connection (aspace-host a) (aspace-port a) (period))))
    (cond ((string? io) (and (string-contains io "refused") #t))
          (else (close-port (car io)) (close-port (cadr io)) #f))))

;;; The standby

;;> What a coordinator calls at the member it chose to stand by for task
;;> \var{id}: answers #t when it does.
(define (become-standby! id kind args poser epoch copy teams coordinator)
  (let ((old (handed-by-id id)))
    (and (not (and old (eq? (handed-role old) 'coordinator)))
         (let ((h (make-handed id kind args poser)))
           (handed-role-set! h 'standby)
           (handed-partner-set! h coordinator)
           (handed-epoch-set! h epoch)
           (handed-task-set! h #f)
           (handed-copy-set! h copy)
           (handed-heard-set! h (monotonic-seconds))
           (handed-teams-set! h teams)
           (handed-took-over-set! h #f)
           (hold-handed! h)
           (thread-start! (make-logged-thread (lambda () (stand-by h)) 'standby))
           #t))))

;;> What the coordinator of task \var{id} calls at its standby at every
;;> change: answers whether this address space stands by for it at
;;> \var{epoch}.
(define (receive-copy id epoch copy)
  (let ((h (handed-by-id id)))
    (and h (eq? (handed-role h) 'standby) (= (handed-epoch h) epoch)
         (begin (handed-copy-set! h copy) #t))))

;;> What the coordinator of task \var{id} calls at its standby when a
;;> member of a step's team, \var{team-id}, arrives at a barrier or sends
;;> a letter, before the member hears back: answers whether this address
;;> space stands by for it at \var{epoch}.
(define (receive-team-copy id epoch team-id state)
  (let ((h (handed-by-id id)))
    (and h (eq? (handed-role h) 'standby) (= (handed-epoch h) epoch)
         (begin (set-team! h team-id state) #t))))

(define (set-team! h team-id state)
  (with-lock *handed-lock*
    (lambda ()
      (handed-teams-set! h (cons (list team-id state)
                                 (remove (lambda (x) (eq? (car x) team-id))
                                         (handed-teams h)))))))

;; The team-keeper of a detached task's steps: (keep-team ID TEAM-ID) the
;; state its coordinator, or the standby that took over, holds of the
;; team, or #f; (keep-team ID TEAM-ID STATE) holds it, and gives it to
;; the standby.  A standby that does not answer is found lost by
;; keep-watch, and the next is given every team as it is then.
(define (keep-team id team-id . state)
  (let ((h (handed-by-id id)))
    (cond ((not h) #f)
          ((null? state)
           (cond ((assq team-id (handed-teams h)) => cadr) (else #f)))
          (else
           (set-team! h team-id (car state))
           (let ((uid (handed-partner h)))
             (if (and uid (eq? (handed-role h) 'coordinator))
                 (guard (e ((remote-error? e)
                            (log-warn "task " id ": the standby " uid " took no copy of "
                                      team-id ": " (error-message e))))
                   (parameterize ((remote-timeout (period)))
                     (remote-apply (uid->aspace uid) receive-team-copy id
                                   (handed-epoch h) team-id (car state))))))))))

;; Takes over when no ping has been answered for take-over-periods, or a
;; period after the coordinator's process is found gone.
(define (stand-by h)
  (let loop ((last (monotonic-seconds)))
    (thread-sleep! (max 0 (- (+ last (period)) (monotonic-seconds))))
    (when (eq? (handed-role h) 'standby)
      (let* ((uid (handed-partner h))
             (started (monotonic-seconds))
             (answer (if (copy-results (handed-copy h))
                         #t       ; ended: the copy holds the results
                         (guard (e (#t (if (gone-by? e uid) 'gone 'silent)))
                       (parameterize ((remote-timeout (period)))
                         (remote-apply (uid->aspace uid) coordinator-ping (handed-id h)
                                       (handed-epoch h)))))))
        (if (eq? answer #t) (handed-heard-set! h (monotonic-seconds)))
        (cond
         ((kept-enough? (handed-copy h)) (drop-handed! h))
         ((copy-results (handed-copy h)) (loop started))
         ((memq answer '(gone #f))
          (log-warn "task " (handed-id h) ": its coordinator " uid " is gone")
          (thread-sleep! (period))  ; it stopped acting a period ago at least
          (take-over! h (list uid)))
         ((>= (- (monotonic-seconds) (handed-heard h)) (* (take-over-periods) (period)))
          (log-warn "task " (handed-id h) ": its coordinator " uid " is silent for "
                    (take-over-periods) " periods")
          (take-over! h (list uid)))
         (else (loop started)))))))

;; This address space becomes h's coordinator, at a new epoch.
(define (take-over! h excluded)
  (handed-role-set! h 'coordinator)
  (handed-epoch-set! h (+ 1 (handed-epoch h)))
  (handed-partner-set! h #f)
  (handed-took-over-set! h (utc-seconds))
  (log-note "task " (handed-id h) ": taking over as its coordinator, epoch "
            (handed-epoch h) ", at " (handed-took-over h))
  (let ((copy (handed-copy h)))
    (cond
     ((copy-results copy) #f)
     (else
      (handed-task-set!
       h (parameterize ((heartbeat-patience detached-patience) (team-keeper keep-team))
           (if (eq? (handed-kind h) 'steps)
               (adopt-steps h copy)
               (adopt-task (handed-id h) (copy-turn copy)
                           (adoption-plan (handed-id h) (copy-status copy))
                           (handed-args h))))))))
  (coordinate! h))

;; (STATE ATTEMPTS UID) for each component of task id: UID where it is to
;; be adopted, else #f.  One found running anywhere is adopted there,
;; whatever the copy says (its start may have come after the copy), as is
;; one found ended that the copy has running there, or not yet started.
(define (adoption-plan id statuses)
  (let ((seen (if (every (lambda (s) (memq (car (status-state s)) '(done failed))) statuses)
                  '()                   ; a finished step's: none to look for
                  (components-of id))))
    (map (lambda (s)
           (let* ((k (status-index s)) (state (status-state s))
                  (running (find (lambda (x) (and (= (cadr x) k) (eq? (car (cddr x)) 'running)))
                                 seen))
                  (ended (find (lambda (x)
                                 (and (= (cadr x) k)
                                      (if (eq? (car state) 'running)
                                          (eq? (car x) (cadr state))
                                          (and (memq (car state) '(negotiating waiting holding))
                                               (null? (status-attempts s))))))
                               seen)))
             (list state (status-attempts s)
                   (cond (running (car running))
                         ((memq (car state) '(done failed)) #f)
                         (ended (car ended))
                         (else #f)))))
         statuses)))

;; The task record of h's task of steps, taken over with copy: each step
;; known is adopted as adopt-task adopts a task, so that no step starts
;; twice, and no finished step's results are lost.
(define (adopt-steps h copy)
  (let* ((args (handed-args h)) (copied (copy-status copy)))
    (resume-steps
     (handed-id h) (car args) (map (lambda (parts) (apply task-step parts)) (cadr args))
     (car (cddr args))
     (lambda (i id step-args)
       ;; Only the step after the copy's last may have begun unseen.
       (let ((entry (find (lambda (e) (= (step-status-index e) i)) copied)))
         (and (<= i (+ 1 (length copied)))
              (let ((plan (adoption-plan
                           id
                           (if entry
                               (step-status-entries entry)
                               (map (lambda (k) (list k '(negotiating) '()))
                                    (iota (cadr step-args) 1))))))
                (and (or entry (any plan-uid plan))
                     (adopt-task id (and entry (= i (length copied)) (copy-turn copy))
                                 plan step-args)))))))))

;; (UID INDEX running|ended) for each component of task id in the lab.
(define (components-of id)
  (append-map (lambda (answer)
                (map (lambda (x) (cons (car answer) x)) (cadr answer)))
              (guard (e (#t '()))
                (parameterize ((remote-timeout (max 1 (period))))
                  (request 'all
                           (sendable-lambda ()
                             (append
                              (filter-map (lambda (r) (and (eq? (car r) id)
                                                           (list (cadr r) 'running)))
                                          (components-running))
                              (filter-map (lambda (e) (and (eq? (ended-id e) id)
                                                           (list (ended-index e) 'ended)))
                                          (components-ended)))))))))

;;; Letting a task go, and adopting it

;; What t's rank and deadline are made of, as data that travels: (WAIT
;; HOLD PRIORITY DEADLINE POSED), DEADLINE a utc-seconds or #f.  A task
;; of steps waits in its step's turn, the last begun.
(define (task-turn-copy t)
  (let ((turn (task-turn (if (pair? (task-steps t)) (last (task-steps t)) t))))
    (and turn
         (list (turn-wait? turn) (turn-hold? turn) (turn-priority turn)
               (and (turn-deadline turn)
                    (+ (utc-seconds) (- (turn-deadline turn) (monotonic-seconds))))
               (turn-posed turn)))))

(define (turn-of-copy copy)
  (and copy
       (apply (lambda (wait hold priority deadline posed)
                (make-turn wait hold priority
                           (and deadline (+ (monotonic-seconds) (- deadline (utc-seconds))))
                           posed))
              copy)))

;; The record of a detached task taken over here.  A task none of whose
;; components started is negotiated again, at its rank; otherwise each is
;; adopted where it runs, kept as it ended, or moved on as a lost robot's.
(define (adopt-task id turn-copy plan args)
  (let-values (((t priorities) (task-of-args id (turn-of-copy turn-copy) args)))
    (for-each (lambda (c p)
                (component-state-set! c (plan-state p))
                (component-attempts-set! c (plan-attempts p)))
              (task-components t) plan)
    (thread-start!
     (make-logged-thread
      (inheriting
       (lambda ()
         (cond
          ((every (lambda (p) (and (not (plan-uid p))
                                   (memq (car (plan-state p)) '(negotiating waiting holding))))
                  plan)
           (for-each (lambda (c) (component-state-set! c '(negotiating)))
                     (task-components t))
           (run-task t priorities))
          (else
           (task-state-set! t 'running)
           (task-team-set! t (map plan-robot plan))
           (supervise-all t (map (lambda (c p) (lambda () (go-on t c p)))
                                 (task-components t) plan))))))
      id))
    t))

(define (plan-state p) (car p))
(define (plan-attempts p) (cadr p))
(define (plan-uid p) (car (cddr p)))

;; Where the component of plan entry p runs, or last ran.
(define (plan-robot p)
  (or (plan-uid p) (state-uid (plan-state p))
      (and (pair? (plan-attempts p)) (car (last (plan-attempts p))))))

(define (state-uid state)
  (case (car state)
    ((running) (cadr state))
    ((reassigned) (car (cddr state)))
    (else #f)))

(define (go-on t c p)
  (let ((state (plan-state p)) (uid (plan-uid p)))
    (cond (uid
           (if (not (equal? (state-uid state) uid))
               (component-state-set! c (list 'running uid (utc-seconds))))
           (supervise t c uid 'adopted))
          ((memq (car state) '(done failed)) #f)
          (else
           (after-attempt t c (state-uid state)
                          '(lost "it was found nowhere when its standby took over"))))))

;;; Finding a detached task from anywhere

;;> This address space's entry for each detached task it holds: (ID ROLE
;;> EPOCH STATE COORDINATOR STANDBY POSER TOOK-OVER), read by the
;;> lab-task- procedures.
(define (handed-entries)
  (map (lambda (h)
         (let ((me (local-aspace-uid)) (role (handed-role h)))
           (list (handed-id h) role (handed-epoch h) (copy-state (handed-copy h))
                 (if (eq? role 'standby) (handed-partner h) me)
                 (if (eq? role 'standby) me (handed-partner h))
                 (handed-poser h) (handed-took-over h))))
       (with-lock *handed-lock* (lambda () *handed*))))

;;> The task's id in \var{e}, an entry of lab-tasks or handed-entries.
(define (lab-task-id e) (car e))
;;> The role of the address space that gave \var{e}, an entry of
;;> lab-tasks: coordinator, standby or let-go.
(define (lab-task-role e) (cadr e))
;;> How many coordinators the task of \var{e} has had.
(define (lab-task-epoch e) (list-ref e 2))
;;> The state of the task of \var{e}, an entry of lab-tasks.
(define (lab-task-state e) (list-ref e 3))
;;> The coordinator's uid in \var{e}, an entry of lab-tasks.
(define (lab-task-coordinator e) (list-ref e 4))
;;> The standby's uid in \var{e}, or #f while there is none.
(define (lab-task-standby e) (list-ref e 5))
;;> The uid that posed the task of \var{e}.
(define (lab-task-poser e) (list-ref e 6))
;;> When the coordinator of \var{e} took the task over, or #f.
(define (lab-task-took-over e) (list-ref e 7))

;;> The lab's detached tasks, one entry each, as its coordinator (or, in
;;> a takeover, its standby) says: see handed-entries.
(define (lab-tasks)
  (let ((all (append-map cadr (guard (e (#t '()))
                                (request 'lab-tasks handed-entries)))))
    (filter-map (lambda (id) (best-entry (filter (lambda (e) (eq? (lab-task-id e) id)) all)))
                (delete-duplicates (map lab-task-id all)))))

;; Of the entries for one task, the coordinator's of the latest epoch, else
;; the standby's.
(define (best-entry entries)
  (let ((ranked (list-sort (lambda (a b)
                             (or (> (lab-task-epoch a) (lab-task-epoch b))
                                 (and (= (lab-task-epoch a) (lab-task-epoch b))
                                      (eq? (lab-task-role a) 'coordinator))))
                           (remove (lambda (e) (eq? (lab-task-role e) 'let-go)) entries))))
    (and (pair? ranked) (car ranked))))

;; The uid that answers for task id now; moving while the only member
;; that holds it has let it go, its standby silent (it takes the task
;; back, or the standby takes it over, within take-over-periods); or #f.
(define (holder-of id)
  (let* ((entries (append-map cadr
                              (guard (e (#t '()))
                                (parameterize ((remote-timeout (max 1 (* 2 (period)))))
                                  (request 'lab-tasks
                                           (sendable-lambda ()
                                             (filter (lambda (e) (eq? (lab-task-id e) id))
                                                     (handed-entries))))))))
         (e (best-entry entries)))
    (cond (e (if (eq? (lab-task-role e) 'standby)
                 (lab-task-standby e)
                 (lab-task-coordinator e)))
          ((pair? entries) 'moving)
          (else #f))))

;; Applies proc to id's record where it is held, waiting while it moves;
;; raises a clear error when nobody holds it.
(define (at-holder who id moving proc . args)
  (let ((moving-until (+ (monotonic-seconds) moving)))
    (let try ((left 2))
      (let ((uid (holder-of id)))
        (cond
         ((and (eq? uid 'moving) (< (monotonic-seconds) moving-until))
          (thread-sleep! (period))
          (try left))
         ((and (memq uid '(#f moving)) (> left 0)) (thread-sleep! (period)) (try (- left 1)))
         ((eq? uid 'moving) (error (string-append who ": " (moving-text id))))
         ((not uid) (error (string-append who ": " (not-held-text id))))
         (else
          (guard (e ((and (remote-error? e) (not (remote-raised-error? e)) (> left 0))
                     (thread-sleep! (period))
                     (try (- left 1))))
            (apply remote-apply (uid->aspace uid) proc id args))))))))

;; How long to wait for a task that moves (take-over-periods).
(define (moving-seconds) (* (+ (take-over-periods) 4) (period)))

(define (moving-text id)
  (string-append "the task " (symbol->string id) " is moving: the member that"
                 " coordinated it let it go, its standby silent (stalled, or cut off"
                 " from it); one of them takes it, or it fails; ask again in a moment"))

(define (not-held-text id)
  (let ((seen (components-of id)))
    (string-append
     "no address space of the lab holds the task " (symbol->string id)
     (if (pair? seen)
         (string-append
          ": it failed, its coordinator and its standby both lost; its components"
          " stopped as orphans on " (uid-list-text (delete-duplicates (map car seen))))
         (string-append
          ": no such task, or it ended more than keep-results seconds ago,"
          " or its coordinator and its standby were both lost")))))

(define (uid-list-text uids)
  (let ((out (open-output-string)))
    (for-each (lambda (u i) (if (> i 0) (write-string ", " out)) (display u out))
              uids (iota (length uids)))
    (get-output-string out)))

;;> What task-status answers for the detached task \var{id}, here where
;;> it is held.
(define (handed-status id)
  (let ((h (handed-by-id id)))
    (cond ((not h) (error "no such detached task here" id))
          ((and (handed-task h) (eq? (handed-role h) 'coordinator)
                (not (copy-results (handed-copy h))))
           (task-status (handed-task h)))
          (else (copy-status (handed-copy h))))))

;;> What task-wait waits for, here where the detached task \var{id} is
;;> held: (done RESULTS), or (not-yet) after \var{seconds}.
(define (handed-wait id seconds)
  (let ((h (handed-by-id id)))
    (cond ((not h) (error "no such detached task here" id))
          ((copy-results (handed-copy h)) (list 'done (copy-results (handed-copy h))))
          ((and (handed-task h) (eq? (handed-role h) 'coordinator))
           (guard (e ((error-object? e) '(not-yet)))
             (list 'done (task-wait (handed-task h) seconds))))
          (else (thread-sleep! (min seconds (period))) '(not-yet)))))

;;> What cancel-task does, here where the detached task \var{id} is
;;> held.
(define (handed-cancel id)
  (let ((h (handed-by-id id)))
    (cond ((and h (handed-task h) (eq? (handed-role h) 'coordinator))
           (cancel-task (handed-task h)))
          (else (error "task is not coordinated here now" id)))))

;;; By id or by record

;;> The state of each component of \var{task}, a task record or a
;;> detached task's id: see task-status in (murdoch task life-cycle).
(define (task-status task)
  (if (symbol? task)
      (at-holder "task-status" task (moving-seconds) handed-status)
      (status-here task)))

;;> Waits for \var{task}, a record or a detached task's id, as task-wait
;;> in (murdoch task life-cycle); a detached task is waited for where it
;;> is coordinated, and found again after a takeover.
(define (task-wait task . seconds)
  (if (symbol? task)
      (let ((until (and (pair? seconds) (+ (monotonic-seconds) (car seconds)))))
        (let loop ()
          (let* ((left (if until (- until (monotonic-seconds)) 10))
                 ;; A task that moves is waited for as one that runs.
                 (answer (parameterize ((remote-timeout (+ (min left 10) 5)))
                           (at-holder "task-wait" task (if until (max 0 left) 3600)
                                      handed-wait (max 0 (min left 10))))))
            (cond ((eq? (car answer) 'done) (cadr answer))
                  ((and until (<= (- until (monotonic-seconds)) 0))
                   (error (string-append "task-wait: " (symbol->string task)
                                         " is not done within "
                                         (number->string (car seconds)) " s")))
                  (else (loop))))))
      (apply wait-here task seconds)))

;;> Cancels \var{task}, a record or a detached task's id, as cancel-task
;;> in (murdoch task life-cycle).
(define (cancel-task task)
  (if (symbol? task)
      (at-holder "cancel-task" task (moving-seconds) handed-cancel)
      (cancel-here task)))
