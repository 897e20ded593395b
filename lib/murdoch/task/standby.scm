;;;; The standby, part of (murdoch task detached): it takes a detached
;;;; task over when its coordinator is lost, and adopts its components
;;;; where they are.

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
  (with-lock (handing-lock (the-handing))
    (lambda ()
      (handed-teams-set! h (cons (list team-id state)
                                 (remove (lambda (x) (eq? (car x) team-id))
                                         (handed-teams h)))))))

;; The team-keeper of a detached task's steps: (keep-team ID TEAM-ID) the
;; team's state held here, or #f; (keep-team ID TEAM-ID STATE) holds it
;; and gives it to the standby, or to the next once keep-watch finds it lost.
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
