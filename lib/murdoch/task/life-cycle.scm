;;;; Tasks that survive failure: the task life cycle (after MURDOCH 2002).
;;
;; start-task poses a task as pose-task does and answers at once with a
;; task record, which task-status, task-wait and cancel-task read.  A
;; component's robot silent for lost-periods, gone or failing has it
;; started again elsewhere when it is restartable; a component whose
;; poser is silent for orphan-periods stops (running.scm).  docs/tasks.md
;; tells the life cycle step by step.

;;; The poser's side


;;> Poses a task as pose-task does, with the same arguments, and answers
;;> at once with its task record.  \var{options} are the components'
;;> priorities (as pose-task's), and then a list with a boolean for each
;;> component: #t when a component whose robot is lost may be given to
;;> another robot (see the header of lib/murdoch/task/life-cycle.scm); by default
;;> none may, and a lost robot's component fails, as in the thesis.
;;> After them, or instead, come keywords and their values: \scheme{wait}
;;> #t or #f, whether the task waits when too few capable robots are free
;;> (default: the lab's when-robots-busy); \scheme{priority}, the task's
;;> priority (default (pose-task-priority)); \scheme{deadline}, seconds
;;> after which a task not yet started fails with \scheme{deadline};
;;> \scheme{detach} #t hands the task to the lab, and answers its id
;;> (lib/murdoch/task/detached.scm).
(define (start-task task-name num-robots capability-list metrics procs . options)
  (let-values (((t priorities)
                (task-of-args #f #f (cons* task-name num-robots capability-list metrics
                                           procs options))))
    (thread-start!
     (make-logged-thread (inheriting (lambda () (run-task t priorities))) (task-id t)))
    t))

;; A new task record from start-task's arguments, args, and its
;; priorities: its id is id, or a new one when id is #f; its turn is
;; turn, or the keywords' when turn is #f (a detached task taken over
;; keeps its own, detached.scm).
(define (task-of-args id turn args)
  (apply
   (lambda (task-name num-robots capability-list metrics procs . options)
     (let* ((lists (take-while list? options))
            (priorities (if (pair? lists) (car lists) (iota num-robots num-robots -1)))
            (restartable (if (and (pair? lists) (pair? (cdr lists)))
                             (cadr lists)
                             (make-list num-robots #f)))
            (keywords (read-turn "start-task" (drop options (length lists)))))
       (check-task task-name num-robots capability-list metrics procs priorities)
       (if (not (and (list? restartable) (= (length restartable) num-robots)
                     (every boolean? restartable)))
           (error "start-task: restartable is a list of a boolean for each component"
                  restartable))
       (values (new-task (or id ((task-id-maker) task-name)) task-name capability-list metrics
                         procs restartable (or turn keywords))
               priorities)))
   args))

(define (new-task id task-name capability-list metrics procs restartable turn)
  (with-lock (tasks-lock)
    (lambda ()
      (check-waiting-room turn)
      (let ((t (make-task
                id
                task-name
                (map (lambda (k caps metric proc r)
                       (let ((c (make-component k caps metric proc r)))
                         (component-state-set! c '(negotiating))
                         (component-attempts-set! c '())
                         c))
                     (iota (length procs) 1) capability-list metrics procs
                     restartable)
                (make-mailbox))))
        (task-state-set! t 'negotiating)
        (task-why-set! t #f)
        (task-team-set! t '())
        (task-steps-set! t #f)
        (task-turn-set! t turn)
        (task-waiter-set! t #f)
        (task-acted-set! t #f)
        (add-posed! t)
        t))))

;; thunk, to run in a new thread with this thread's pose-task settings:
;; a thread does not inherit its maker's parameters.
(define (inheriting thunk)
  (let ((port (pose-task-progress)) (priority (pose-task-priority))
        (assignment (pose-task-assignment)) (seconds (task-timeout))
        (patience (heartbeat-patience)))
    (lambda ()
      (parameterize ((pose-task-progress port) (pose-task-priority priority)
                     (pose-task-assignment assignment) (task-timeout seconds)
                     (heartbeat-patience patience))
        (thunk)))))

;;> How many times longer than a poser's the components of a task started
;;> under it wait for heartbeats before they stop, and it waits before it
;;> declares their robot lost: a detached task's, so that its standby may
;;> take over before they stop (detached.scm).
(define heartbeat-patience (make-parameter 1))

;;> What makes a new task's id of its name: task-key, NAME@UID/N; a
;;> detached task's coordinator makes ids no peer of the lab knows
;;> (detached.scm).
(define task-id-maker (make-parameter task-key))

;;> Whether \var{t}'s coordinator let it go (detached.scm): it acts no
;;> more.
(define (let-go? t) (eq? (task-state t) 'let-go))

;;> Stops acting for \var{t}, a detached task whose standby may be taking
;;> it over: no heartbeat, start or negotiation more (let-go? checks),
;;> and nothing cancelled; what it holds while it waits is given back.  A
;;> task of steps lets its step go with it.
(define (let-task-go! t)
  (task-state-set! t 'let-go)
  (if (task-waiter t) (tell-waiter! (task-waiter t) '(cancel)))
  (if (pair? (task-steps t)) (let-task-go! (last (task-steps t))))
  (mailbox-put! (task-done t) 'let-go))

;; Negotiates t, runs its components, each watched over by a thread of
;; its own, and puts their results in t's mailbox.
(define (run-task t priorities)
  (let* ((cs (task-components t))
         (team (parameterize ((pose-task-reservation (task-id t)))
                 (negotiate-turn
                  t cs
                  (if (and (turn-hold? (task-turn t)) (> (length cs) 1))
                      (lambda (w) (hold-try w priorities))
                      (lambda (w)
                        (negotiate (task-name t) (length cs)
                                   (map component-capabilities cs)
                                   (map component-metric cs) (map component-proc cs)
                                   priorities)))))))
    (cond
     ((let-go? t) (if (pair? team) (free-team! team)))
     ((eq? team 'deadline)
      (task-state-set! t 'deadline)
      (end-all! t 'deadline)
      (finish! t team))
     ((or (eq? team 'cancelled) (eq? (task-state t) 'cancelled))
      (if (pair? team) (free-team! team))
      (end-all! t 'cancelled)
      (finish! t (map component-result cs)))
     ((symbol? team)
      (for-each (lambda (c)
                  (if (not (eq? (car (component-state c)) 'failed))
                      (fail-component! t c (symbol->string team))))
                cs)
      (finish! t team))
     (else
      (task-state-set! t 'running)
      (task-team-set! t (map winner-uid (negotiated-winners team)))
      (supervise-all t (map (lambda (c winner type)
                              (lambda ()
                                (supervise t c (winner-uid winner)
                                           (work-for winner type c))))
                            cs (negotiated-winners team) (negotiated-types team)))))))

(define (free-team! team)
  (for-each free-winner! (negotiated-winners team) (negotiated-types team)))

;; Runs each thunk, a component's supervision, in a thread of its own,
;; and finishes t once all are over.
(define (supervise-all t thunks)
  (for-each thread-join!
            (map (lambda (thunk) (thread-start! (make-logged-thread (inheriting thunk))))
                 thunks))
  (finish! t (map component-result (task-components t))))

;; Puts each component of t that is not over in state (how): cancelled
;; or deadline.
(define (end-all! t how)
  (for-each (lambda (c)
              (if (not (memq (car (component-state c)) '(done failed)))
                  (component-state-set! c (list how))))
            (task-components t)))

;; Ends t: done only when every component completed, else failed with
;; its first failure's why, or as it was cancelled or ran out of time.
;; A task of steps is done when its last step is.  A task let go
;; finishes here no more: its new coordinator finishes it.
(define (finish! t results)
  (when (not (let-go? t))
    (with-lock (tasks-lock)
      (lambda ()
        (if (not (memq (task-state t) '(cancelled deadline failed)))
            (task-state-set!
             t (if (every (lambda (c) (eq? (car (component-state c)) 'done))
                          (task-components t))
                   'done
                   'failed)))
        (if (and (eq? (task-state t) 'failed) (not (task-why t)))
            (task-why-set! t (first-failure t)))
        (forget-over! (setting 'tasks-kept))))
    (progress (task-id t) ": " (task-state-text t))
    (mailbox-put! (task-done t) results)))

;; The why of t's first component that failed, for a task that failed
;; without fail-component!: a component stopped without word.
(define (first-failure t)
  (let ((failed (find (lambda (c) (eq? (car (component-state c)) 'failed))
                      (task-components t))))
    (if failed (cadr (component-state failed)) "a component did not complete")))

;;> \var{task}'s state as a person reads it: its word (see task-state),
;;> and for a failed task why, as "failed: connection lost".
(define (task-state-text task)
  (if (and (eq? (task-state task) 'failed) (task-why task))
      (string-append "failed: " (task-why task))
      (symbol->string (task-state task))))

;; What a winner runs: (proc arg ...), a promise applied to #t for an
;; exclusive component.
(define (work-for winner type c)
  (if (eq? type 'exclusive)
      (list (winner-promise winner) #t)
      (list (component-proc c))))

;; Runs component c on uid, and elsewhere while its robot is lost and it
;; may restart; work is (PROC ARG ...), or adopted for a detached task's
;; component that a new coordinator found running on uid.
(define (supervise t c uid work)
  (if (not (eq? work 'adopted))
      (component-state-set! c (list 'running uid (utc-seconds))))
  (progress "  component " (component-index c) " starts on " uid)
  (after-attempt t c uid (if (let-go? t) '(let-go) (attempt t c uid work))))

;; Moves c on from its run on uid (#f: none known), which ended with
;; outcome: done, failed, or negotiated again and run elsewhere when it
;; may.
(define (after-attempt t c uid outcome)
  (if (and uid (not (let-go? t)))
      (component-attempts-set! c (append (component-attempts c)
                                         (list (cons uid outcome)))))
  (progress "  component " (component-index c) " " (car outcome) " on " uid ": "
            (case (car outcome)
              ((done) (abridged (cadr outcome) 50))
              ((let-go) "its coordinator let it go")
              (else (cadr outcome))))
  (cond
     ((let-go? t) #f)
     ((eq? (task-state t) 'cancelled)
      (component-state-set! c '(cancelled)))
     ((and (eq? (car outcome) 'lost) (restart? c))
      (component-state-set! c '(negotiating))
      (let ((next (renegotiate t c)))
        (cond
         (next
          (component-state-set! c (list 'reassigned (or uid 'none) (car next)))
          (replace-member! t (component-index c) (car next))
          (progress "  component " (component-index c) " reassigned from "
                    uid " to " (car next))
          (supervise t c (car next) (cdr next)))
         (else
          (fail-component! t c (string-append (cadr outcome)
                                              "; no other capable robot is free"))))))
     ((eq? (car outcome) 'done) (component-state-set! c outcome))
     (else (fail-component! t c (cadr outcome)))))

;; Puts uid in t's team as the robot of component k.  By index, not by
;; the robot it replaces: a robot whose component is done may take
;; another of the task's, and so be in the team twice.  Under the lock:
;; two components may be lost at once.
(define (replace-member! t k uid)
  (with-lock (tasks-lock)
    (lambda ()
      (task-team-set! t (map (lambda (u i) (if (= i k) uid u))
                             (task-team t) (iota (length (task-team t)) 1))))))

(define (restart? c)
  (and (component-restartable? c)
       (< (length (component-attempts c))
          (setting 'max-attempts))))

;; The next robot for c, (uid proc arg ...), or #f: c is negotiated alone,
;; without the robots it had, nor those of the task's other components.
(define (renegotiate t c)
  (parameterize ((pose-task-reservation (task-id t))
                 (pose-task-excluded
                  (append (map car (component-attempts c))
                          (filter-map (lambda (other)
                                        (and (eq? (car (component-state other)) 'running)
                                             (cadr (component-state other))))
                                      (task-components t)))))
    (let ((team (negotiate-turn
                 t (list c)
                 (lambda (w)
                   (negotiate (task-name t) 1 (list (component-capabilities c))
                              (list (component-metric c))
                              (list (component-proc c)))))))
      (and (pair? team)
           (let ((winner (car (negotiated-winners team))))
             (cons (winner-uid winner)
                   (work-for winner (car (negotiated-types team)) c)))))))

;; One run of c on uid, watched by heartbeats: (done VALUE), (failed WHY)
;; or (lost WHY).
(define (attempt t c uid work)
  (let* ((a (uid->aspace uid))
         (period (setting 'heartbeat))
         (patience (heartbeat-patience))
         (answer (make-mailbox))
         (runner (make-logged-thread
                  (call-there a answer (task-id t) (component-index c)
                                     (local-aspace-uid) (* patience period) work))))
    (thread-start! runner)
    ;; A beat goes a period after the last one went, not after its answer
    ;; came: the robot stops a component orphan-periods after the last it
    ;; heard, and on a loaded machine an answer may take most of a period.
    (let watch ((heard (monotonic-seconds)) (due (+ (monotonic-seconds) period)))
      (let* ((got (mailbox-take answer due (lambda () #f)))
             (next (max (+ due period) (monotonic-seconds))))
        (cond
         (got (outcome-of got))
         ;; Its call is not given up: that would stop the component,
         ;; which the new coordinator adopts.
         ((let-go? t) '(let-go))
         ((begin (task-acted-set! t (utc-seconds))
                 (heartbeat a (task-id t) (component-index c) period))
          (watch (monotonic-seconds) next))
         ((>= (- (monotonic-seconds) heard) (* (lost-periods) patience period))
          (thread-interrupt! runner)    ; its call is given up
          (list 'lost (string-append (symbol->string uid) " silent for "
                                     (number->string (* (lost-periods) patience))
                                     " heartbeats")))
         (else (watch heard next)))))))

;; A thunk that runs work on a inside run-component, and puts (value V)
;; or (raised E) in the mailbox answer.
(define (call-there a answer id k poser period work)
  (let ((seconds (task-timeout)))
    (lambda ()
      (mailbox-put!
       answer
       (guard (e (#t (list 'raised e)))
         (list 'value
               (parameterize ((remote-timeout seconds))
                 (if (eq? work 'adopted)
                     (remote-apply a (sendable-lambda () (await-component id k poser)))
                     (remote-apply a (sendable-lambda ()
                                       (run-component id k poser period work)))))))))))

;; Whether the robot a answered a heartbeat within a period.
(define (heartbeat a id k period)
  (guard (e (#t #f))
    (parameterize ((remote-timeout period))
      (remote-apply a (sendable-lambda () (component-heartbeat! id k)))
      #t)))

(define (outcome-of answer)
  (let ((what (cadr answer)))
    (cond
     ((eq? (car answer) 'value)
      (if (and (pair? what) (eq? (car what) 'robot-failure))
          (list 'lost (cadr what))
          (list 'done what)))
     ((remote-unreachable-error? what) (list 'lost (error-message what)))
     (else (list 'failed (error-message what))))))


;;> For each component of \var{task}, in order, (INDEX STATE ATTEMPTS),
;;> read by status-index, status-state and status-attempts:
;;> STATE is (negotiating), (running UID SINCE), (done VALUE), (failed
;;> WHY) or (reassigned FROM TO), SINCE a (utc-seconds); ATTEMPTS has
;;> (UID . OUTCOME) for each robot that had the component and is done
;;> with it, OUTCOME being (done VALUE), (failed WHY) or (lost WHY).
;;> \var{task} may also be a detached task's id, from any peer.
(define (task-status task)
  (check-task-record "task-status" task)
  (if (task-waiter task) (move-up! (task-waiter task)))
  (if (task-steps task)
      (map (lambda (i sub) (list 'step i (task-status sub)))
           (iota (length (task-steps task)) 1) (task-steps task))
      (map (lambda (c)
             (list (component-index c) (component-state c)
                   (component-attempts c)))
           (task-components task))))

;;> Waits for \var{task} to end, at most \var{seconds} (default: for
;;> ever), and answers what pose-task would have: each component's result,
;;> (error UID WHY) for a failed one, or not-enough-takers.  Raises an
;;> error naming the task when the time runs out.  \var{task} may also be a
;;> detached task's id, from any peer.
(define (task-wait task . seconds)
  (check-task-record "task-wait" task)
  (if (pair? seconds)
      (mailbox-take (task-done task) (+ (monotonic-seconds) (car seconds))
                    (lambda ()
                      (error (string-append "task-wait: "
                                            (symbol->string (task-id task))
                                            " is not done within "
                                            (number->string (car seconds)) " s"))))
      ;; A wait takes a finite timeout: an hour at a time.
      (let loop ()
        (or (mailbox-take (task-done task) (+ (monotonic-seconds) 3600)
                          (lambda () #f))
            (loop)))))

;;> Cancels \var{task}: every running component stops on its robot at its
;;> next robot command or remote call, its robot stops, and every
;;> reservation is freed.  A task already over stays as it ended.
;;> Answers #t.  \var{task} may also be a detached task's id, from any
;;> peer.
(define (cancel-task task)
  (check-task-record "cancel-task" task)
  (with-lock (tasks-lock)
    (lambda ()
      (if (not (over? task)) (task-state-set! task 'cancelled))))
  (if (task-waiter task) (tell-waiter! (task-waiter task) '(cancel)))
  (if (task-steps task) (for-each cancel-task (task-steps task)))
  (for-each (lambda (c)
              (let ((state (component-state c)))
                (if (eq? (car state) 'running)
                    (stop-there (cadr state) (task-id task) (component-index c)))))
            (task-components task))
  #t)

(define (stop-there uid id k)
  (guard (e (#t (log-warn "cancel: " uid " did not hear it: " (error-message e))))
    (parameterize ((remote-timeout 1))
      (remote-apply (uid->aspace uid) (sendable-lambda () (stop-component! id k))))))

;;> The tasks of this address space: (posed ID STATE WHY PLACE PRIORITY
;;> HELD WANTS) for each it started that is not over, and the newest of
;;> those over, at most the lab's tasks-kept, newest first; and (running
;;> ID INDEX POSER) for each component it runs.  listed-id and the other
;;> listed- procedures read them.
(define (tasks)
  (let* ((posed (with-lock (tasks-lock) posed-tasks))
         (line (and (any task-waiter posed)
                    (line-ranks-now))))
    (append (map (lambda (t) (posed-entry t line)) posed)
            (map (lambda (r) (cons 'running r)) (components-running)))))

;; t as (tasks) lists it; a waiting task as waiting-entry has it, with
;; its place in line, line the lab's line (line-ranks-now).
(define (posed-entry t line)
  (let ((w (task-waiter t)))
    (if w
        (begin (move-up! w line) (waiting-entry w))
        (list 'posed (task-id t) (task-state t) (task-why t) #f
              (and (task-turn t) (turn-priority (task-turn t))) '() '()))))
