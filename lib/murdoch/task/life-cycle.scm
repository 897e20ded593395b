;;;; Tasks that survive failure: the task life cycle (after MURDOCH 2002).
;;
;; pose-task blocks until its components are done, as in the thesis.
;; start-task poses the same task and answers at once with a task record,
;; which task-status, task-wait and cancel-task read and act on, and it
;; keeps watch over each component while it runs:
;;
;;  1. The task is negotiated as pose-task negotiates it.
;;  2. Each component runs on its robot inside run-component, which
;;     registers it there.  Every (lab-setting lab 'heartbeat) seconds the
;;     poser remote-applies component-heartbeat! on the robot: an answer
;;     tells the poser that the robot lives, its arrival tells the robot
;;     that its poser does.
;;  3. A component's robot is lost when it is silent for lost-periods (four)
;;     heartbeat periods, when its address space is gone (the call's connection is
;;     lost), or when the component raises a robot failure: its trip
;;     connection closed, or its base stalled.  A restartable component
;;     is then negotiated again, without the robots it had and those of
;;     the task's other components, and started again, on at most
;;     max-attempts robots in all.  Any other component is failed, as is
;;     one that raises an ordinary error, as pose-task reports it.
;;  4. A component whose poser is silent for two periods stops on its
;;     robot, at its next robot command or remote call (abandon.scm), and
;;     so frees its reservation: no orphans.  The same rule stops the
;;     component of a robot cut off from its poser at least one full
;;     period before the poser can declare it lost and start the component
;;     elsewhere: no ghosts (running.scm gives the margin).
;;  5. cancel-task stops every component on its robot so, at once, and
;;     what is still being negotiated is freed when the negotiation ends.
;;
;; A task of steps (start-steps) is a sequence of such tasks, one a step.

;;; The poser's side

(define-record-type task
  (make-task id name components done)
  ;;> True for a task record, as start-task and start-steps answer.
  task?
  ;;> A task's id, NAME@UID/N: unique in the lab, as (tasks) shows it.
  (id task-id)
  ;;> The name a task was posed under, a symbol.
  (name task-name)
  (components task-components)          ; a list of components
  (done task-done)                      ; a mailbox: the results, once done
  (state task-state task-state-set!)    ; negotiating running done failed cancelled
  (team task-team task-team-set!)       ; its robots, in component order
  (steps task-steps task-steps-set!)    ; of a task of steps, those started
  (turn task-turn task-turn-set!)       ; how it waits its turn: a turn record
  (waiter task-waiter task-waiter-set!)) ; while it waits, its waiter record

(define-record-type component
  (make-component index capabilities metric proc restartable?)
  component?
  (index component-index)
  (capabilities component-capabilities)
  (metric component-metric)
  (proc component-proc)
  (restartable? component-restartable?)
  ;; (negotiating), (waiting POSITION WHY), (running UID SINCE), (done
  ;; VALUE), (failed WHY) or (reassigned FROM TO); SINCE is a
  ;; (utc-seconds).
  (state component-state component-state-set!)
  (attempts component-attempts component-attempts-set!)) ; ((UID . OUTCOME) ...)

;; Global, as *waiters* and the offers' below: peers' calls find them by name.
(define *posed* '())                    ; the tasks started here, newest first
(define *tasks-lock* (make-mutex 'tasks))

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
;;> after which a task not yet started fails with \scheme{deadline}.
(define (start-task . args)
  (let-values (((t priorities) (task-of-args #f #f args)))
    (thread-start!
     (make-logged-thread (inheriting (lambda () (run-task t priorities))) (task-id t)))
    t))

;; A new task record from start-task's arguments, and its priorities:
;; its id is id, or a new one when id is #f; its turn that of turn-copy
;; (see task-turn-copy), or of the keywords when turn-copy is #f.
(define (task-of-args id turn-copy args)
  (apply
   (lambda (task-name num-robots capability-list metrics procs . options)
     (let* ((lists (take-while list? options))
            (priorities (if (pair? lists) (car lists) (iota num-robots num-robots -1)))
            (restartable (if (and (pair? lists) (pair? (cdr lists)))
                             (cadr lists)
                             (make-list num-robots #f))))
       (check-task task-name num-robots capability-list metrics procs priorities)
       (if (not (and (list? restartable) (= (length restartable) num-robots)
                     (every boolean? restartable)))
           (error "start-task: restartable is a list of a boolean for each component"
                  restartable))
       (let ((turn (read-turn "start-task" (drop options (length lists)))))
         (values (new-task (or id (task-key task-name)) task-name capability-list metrics
                           procs restartable
                           (if turn-copy (turn-of-copy turn-copy) turn))
                 priorities))))
   args))

(define (new-task id task-name capability-list metrics procs restartable turn)
  (with-lock *tasks-lock*
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
        (task-team-set! t '())
        (task-steps-set! t #f)
        (task-turn-set! t turn)
        (task-waiter-set! t #f)
        (set! *posed* (cons t *posed*))
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
;;> under it wait for heartbeats before they stop, and its coordinator
;;> before it declares their robot lost: a detached task's, that a
;;> standby may take over before its components stop (detached.scm).
(define heartbeat-patience (make-parameter 1))

;; Negotiates t, runs its components, each watched over by a thread of
;; its own, and puts their results in t's mailbox.
(define (run-task t priorities)
  (let* ((cs (task-components t))
         (team (negotiate-turn
                t cs
                (if (and (turn-hold? (task-turn t)) (> (length cs) 1))
                    (lambda (w) (hold-try w priorities))
                    (lambda (w)
                      (negotiate (task-name t) (length cs)
                                 (map component-capabilities cs)
                                 (map component-metric cs) (map component-proc cs)
                                 priorities))))))
    (cond
     ((let-go? t) (if (pair? team) (free-team! team)))
     ((and (symbol? team) (not (eq? team 'cancelled)))
      (if (memq (task-state t) '(negotiating waiting)) (task-state-set! t 'failed))
      (for-each (lambda (c)
                  (if (not (eq? (car (component-state c)) 'failed))
                      (component-state-set! c (list 'failed team))))
                cs)
      (finish! t team))
     ((symbol? team)
      (for-each (lambda (c) (component-state-set! c '(failed "cancelled"))) cs)
      (finish! t (map component-result cs)))
     ((eq? (task-state t) 'cancelled)
      (free-team! team)
      (for-each (lambda (c) (component-state-set! c '(failed "cancelled"))) cs)
      (finish! t (map component-result cs)))
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

(define (finish! t results)
  (if (memq (task-state t) '(negotiating waiting running)) (task-state-set! t 'done))
  (if (not (let-go? t)) (finish-told! t results)))

(define (finish-told! t results)
  (progress (task-id t) ": " (task-state t))
  (mailbox-put! (task-done t) results))

;; What a winner runs: (proc arg ...), a promise applied to #t for an
;; exclusive component.
(define (work-for winner type c)
  (if (eq? type 'exclusive)
      (list (winner-promise winner) #t)
      (list (component-proc c))))

(define (free-winner! winner type)
  (if (eq? type 'exclusive)
      (guard (e (#t #f)) ((winner-promise winner) #f))))

;; Runs component c on uid, and again elsewhere while its robot is lost
;; and it may be restarted.
(define (supervise t c uid work)
  (if (not (eq? work 'adopted))
      (component-state-set! c (list 'running uid (utc-seconds))))
  (progress "  component " (component-index c) " starts on " uid)
  (after-attempt t c uid (if (let-go? t) '(let-go) (attempt t c uid work))))

;; Moves c on from its run on uid, which ended with outcome: done,
;; failed, or negotiated again and run elsewhere when it may.
(define (after-attempt t c uid outcome)
  (if (not (or (let-go? t) (not uid)))
      (component-attempts-set! c (append (component-attempts c)
                                         (list (cons uid outcome)))))
  (progress "  component " (component-index c) " on " uid ": " outcome)
  (cond
     ((let-go? t) #f)
     ((eq? (task-state t) 'cancelled)
      (component-state-set! c '(failed "cancelled")))
     ((and (eq? (car outcome) 'lost) (restart? c))
      (let ((next (renegotiate t c)))
        (cond
         (next
          (component-state-set! c (list 'reassigned (or uid 'none) (car next)))
          (replace-member! t (component-index c) (car next))
          (progress "  component " (component-index c) " reassigned from "
                    uid " to " (car next))
          (supervise t c (car next) (cdr next)))
         (else
          (component-state-set!
           c (list 'failed (string-append (cadr outcome)
                                          "; no other capable robot is free")))))))
     ((eq? (car outcome) 'done) (component-state-set! c outcome))
     (else (component-state-set! c (list 'failed (cadr outcome))))))

;; Puts uid in t's team as the robot of component k.  By index, not by
;; the robot it replaces: a robot whose component is done may take
;; another of the task's, and so be in the team twice.  Under the lock:
;; two components may be lost at once.
(define (replace-member! t k uid)
  (with-lock *tasks-lock*
    (lambda ()
      (task-team-set! t (map (lambda (u i) (if (= i k) uid u))
                             (task-team t) (iota (length (task-team t)) 1))))))

(define (restart? c)
  (and (component-restartable? c)
       (< (length (component-attempts c))
          (lab-setting (current-lab) 'max-attempts))))

;; The next robot for c, (uid proc arg ...), or #f: c is negotiated alone,
;; without the robots it had, nor those of the task's other components.
(define (renegotiate t c)
  (parameterize ((pose-task-excluded
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
         (period (lab-setting (current-lab) 'heartbeat))
         (patience (heartbeat-patience))
         (answer (make-mailbox))
         (runner (make-logged-thread
                  (call-there a answer (task-id t) (component-index c)
                                     (local-aspace-uid) (* patience period) work))))
    (thread-start! runner)
    (let watch ((heard (monotonic-seconds)))
      (let ((got (mailbox-take answer (+ (monotonic-seconds) period)
                               (lambda () #f))))
        (cond
         (got (outcome-of got))
         ((let-go? t) (thread-interrupt! runner) '(let-go))
         ((heartbeat a (task-id t) (component-index c) period)
          (watch (monotonic-seconds)))
         ((>= (- (monotonic-seconds) heard) (* lost-periods patience period))
          (thread-interrupt! runner)    ; its call is given up
          (list 'lost (string-append (symbol->string uid) " silent for "
                                     (number->string (* lost-periods patience))
                                     " heartbeats")))
         (else (watch heard)))))))

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

;; A component's result, as pose-task gives it: its value, or (error UID
;; WHY) with the last robot it had.
(define (component-result c)
  (let ((state (component-state c)))
    (if (eq? (car state) 'done)
        (cadr state)
        (list 'error (let ((attempts (component-attempts c)))
                       (and (pair? attempts) (car (last attempts))))
              (cadr state)))))

;;> For each component of \var{task}, in order, (INDEX STATE ATTEMPTS),
;;> read by status-index, status-state and status-attempts:
;;> STATE is (negotiating), (running UID SINCE), (done VALUE), (failed
;;> WHY) or (reassigned FROM TO), SINCE a (utc-seconds); ATTEMPTS has
;;> (UID . OUTCOME) for each robot that had the component and is done
;;> with it, OUTCOME being (done VALUE), (failed WHY) or (lost WHY).
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

;;> The component's number in \var{s}, an entry of task-status.
(define (status-index s) (car s))

;;> The component's state in \var{s}, an entry of task-status:
;;> (negotiating), (running UID SINCE), (done VALUE) ...
(define (status-state s) (cadr s))

;;> The (UID . OUTCOME) of each robot done with the component in \var{s},
;;> an entry of task-status.
(define (status-attempts s) (car (cddr s)))

;;> Whether \var{s}, an entry of task-status, is a step's (step I
;;> STATUS), as a task of steps gives.
(define (step-status? s) (eq? (car s) 'step))

;;> The number I of the step in \var{s}, a step's entry of task-status.
(define (step-status-index s) (cadr s))

;;> The STATUS in \var{s}, a step's entry of task-status: the step's own
;;> task-status, an entry for each of its components.
(define (step-status-entries s) (car (cddr s)))

;;> Waits for \var{task} to end, at most \var{seconds} (default: for
;;> ever), and answers what pose-task would have: each component's result,
;;> (error UID WHY) for a failed one, or not-enough-takers.  Raises an
;;> error naming the task when the time runs out.
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
;;> reservation is freed.  Answers #t.
(define (cancel-task task)
  (check-task-record "cancel-task" task)
  (task-state-set! task 'cancelled)
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

(define (check-task-record who x)
  (if (not (task? x))
      (error (string-append who ": not a task; start-task answers one") x)))

;;> The tasks of this address space: (posed ID STATE) for each it started,
;;> newest first, (posed ID waiting PLACE WHY) for one waiting its turn,
;;> and (running ID INDEX POSER) for each component it runs.  listed-id
;;> and the other listed- procedures read them.
(define (tasks)
  (append (map (lambda (t)
                 (let ((w (task-waiter t)))
                   (if (and w (eq? (task-state t) 'waiting))
                       (list 'posed (task-id t) 'waiting (waiter-position w)
                             (waiter-why w))
                       (list 'posed (task-id t) (task-state t)))))
               (with-lock *tasks-lock* (lambda () *posed*)))
          (map (lambda (r) (cons 'running r)) (components-running))))

;;> Whether \var{e}, an entry of (tasks), is a task started here.
(define (listed-posed? e) (eq? (car e) 'posed))

;;> The task id of \var{e}, an entry of (tasks).
(define (listed-id e) (cadr e))

;;> The state of \var{e}, a posed entry of (tasks): waiting, running,
;;> done ...
(define (listed-state e) (car (cddr e)))

;;> The place in line of \var{e}, a posed entry of (tasks), when it
;;> waits, else #f.
(define (listed-place e) (and (= (length e) 5) (list-ref e 3)))

;;> Why \var{e}, a posed entry of (tasks) that waits, waits: a string for
;;> each task ahead of it.
(define (listed-why e) (list-ref e 4))

;;> The component's number in \var{e}, a running entry of (tasks).
(define (listed-index e) (car (cddr e)))

;;> The poser of the component in \var{e}, a running entry of (tasks).
(define (listed-poser e) (cadr (cddr e)))

;;; Tasks handed to the lab (detached.scm): what their coordinators need

(define (let-go? t) (eq? (task-state t) 'let-go))

;;> Stops acting for \var{t}, a detached task whose standby may be taking
;;> it over: no heartbeat, start or negotiation more, and nothing is
;;> cancelled; what it holds while it waits is given back.
(define (let-task-go! t)
  (task-state-set! t 'let-go)
  (if (task-waiter t) (tell-waiter! (task-waiter t) '(cancel)))
  (if (task-steps t) (for-each let-task-go! (task-steps t)))
  (mailbox-put! (task-done t) 'let-go))

;;> What \var{t}'s rank and deadline are made of, as data that travels:
;;> (WAIT HOLD PRIORITY DEADLINE POSED), DEADLINE a utc-seconds or #f.
(define (task-turn-copy t)
  (let ((turn (task-turn t)))
    (and turn
         (list (turn-wait? turn) (turn-hold? turn) (turn-priority turn)
               (and (turn-deadline turn)
                    (+ (utc-seconds) (- (turn-deadline turn) (monotonic-seconds))))
               (turn-posed turn)))))

(define (turn-of-copy copy)
  (apply (lambda (wait hold priority deadline posed)
           (make-turn wait hold priority
                      (and deadline (+ (monotonic-seconds) (- deadline (utc-seconds))))
                      posed))
         copy))

;;> A detached task taken over by a new coordinator, as a task record:
;;> \var{id} and \var{turn-copy} (task-turn-copy) are the task's, args
;;> start-task's, and \var{plan} has (STATE ATTEMPTS UID) for each
;;> component, UID the robot where it runs or ended lately, or #f.  A
;;> task none of whose components started is negotiated again, at its
;;> rank; otherwise each component is adopted where it runs, kept as it
;;> ended, or, found nowhere, moved on as a lost robot's.
(define (adopt-task id turn-copy plan args)
  (let-values (((t priorities) (task-of-args id turn-copy args)))
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
                                   (memq (car (plan-state p)) '(negotiating waiting))))
                  plan)
           (for-each (lambda (c) (component-state-set! c '(negotiating)))
                     (task-components t))
           (run-task t priorities))
          (else
           (task-state-set! t 'running)
           (task-team-set! t (map (lambda (p) (or (plan-uid p) (state-uid (plan-state p))))
                                  plan))
           (supervise-all t (map (lambda (c p) (lambda () (go-on t c p)))
                                 (task-components t) plan))))))
      id))
    t))

;; The parts of an entry of adopt-task's plan.
(define (plan-state p) (car p))
(define (plan-attempts p) (cadr p))
(define (plan-uid p) (car (cddr p)))

;; The robot a component's state names, or #f.
(define (state-uid state)
  (case (car state)
    ((running) (cadr state))
    ((reassigned) (car (cddr state)))
    (else #f)))

;; Component c of an adopted task goes on from its entry p of the plan.
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

;;> The parts of a step made by task-step, as that travels: its
;;> capabilities, metrics, procedures and options, task-step's arguments.
(define (step-parts s)
  (cons* (step-capabilities s) (step-metrics s) (step-procs s) (step-options s)))

;;; Tasks of several steps (thesis ch. 6: pose-task with MOVER's
;;; synchronization)
;;
;; A task of steps runs its steps in order, each a task as start-task runs
;; one: a step starts when every component of the step before is done (a
;; barrier), and its procedures are applied to that step's results.  Its
;; components may ask for a robot that had a component of an earlier step,
;; so that a team keeps its members, and run as a team: team-barrier,
;; team-send! and team-receive (team.scm) reach the other members.  A step
;; with a failed component stops the task; everything is freed as each
;; step's components end.

(define-record-type step
  (make-step capabilities metrics procs options)
  step?
  (capabilities step-capabilities)
  (metrics step-metrics)
  (procs step-procs)
  (options step-options))

;;> A step of a task of steps: start-task's lists, one entry per component,
;;> then optionally its priorities and its restartable list.  A capability
;;> entry (same J K) asks for the robot that had component K of step J.
;;> Each procedure is applied to the list of the step before's results
;;> ('() for the first step), on its robot, as a member of the step's team.
(define (task-step capability-list metrics procs . options)
  (if (not (and (list? capability-list) (list? metrics) (list? procs)
                (= (length capability-list) (length metrics) (length procs))))
      (error "task-step: capabilities, metrics and procedures are lists of one length"))
  (make-step capability-list metrics procs options))

;;> Starts a task of \var{steps} (made by task-step) and answers its task
;;> record at once; start-task's keywords may follow the steps, and each
;;> step is started with them.  task-status gives (step I STATUS) for each
;;> step started (read by step-status? and the other step-status-
;;> procedures), task-wait the list of each step's results, and
;;> cancel-task stops the step running and those after it.
(define (start-steps task-name . steps+options)
  (let ((steps (take-while step? steps+options))
        (options (drop-while step? steps+options)))
    (if (not (and (symbol? task-name) (pair? steps)))
        (error "start-steps: a task name, then one or more steps made by task-step"))
    (read-turn "start-steps" options)
    (for-each check-same steps (iota (length steps) 1))
    (let ((t (new-task (task-key task-name) task-name '() '() '() '() #f)))
      (task-steps-set! t '())
      (thread-start!
       (make-logged-thread (inheriting (lambda () (run-steps t steps options)))
                           (task-id t)))
      t)))

;;> Runs a task of steps and answers, as task-wait, each step's results.
(define (pose-steps task-name . steps)
  (task-wait (apply start-steps task-name steps)))

(define (same? capability)
  (and (pair? capability) (eq? (car capability) 'same)))

;; A (same J K) entry of step i names a component of an earlier step.
(define (check-same s i)
  (for-each (lambda (c)
              (if (and (same? c)
                       (not (and (= (length c) 3) (exact-integer? (cadr c))
                                 (< 0 (cadr c) i) (exact-integer? (car (cddr c))))))
                  (error (string-append "task-step: (same J K) names component K"
                                        " of a step J before this one")
                         c)))
            (step-capabilities s)))

(define (run-steps t steps options)
  (let loop ((i 1) (steps steps) (previous '()) (results '()))
    (cond
     ((or (null? steps) (eq? (task-state t) 'cancelled))
      (finish! t (reverse results)))
     (else
      (let* ((sub #f)
             (coordinator (make-coordinator (lambda () (if sub (task-team sub) '()))))
             (step-results
              (begin
                (set! sub (start-step t (car steps) i previous coordinator options))
                (task-steps-set! t (append (task-steps t) (list sub)))
                (task-wait sub))))
        (release-proxy! coordinator)
        (progress (task-id t) ": step " i " done: " step-results)
        (if (step-failed? step-results)
            (begin (if (not (eq? (task-state t) 'cancelled)) (task-state-set! t 'failed))
                   (finish! t (reverse (cons step-results results))))
            (loop (+ i 1) (cdr steps) step-results (cons step-results results))))))))

(define (step-failed? results)
  (or (symbol? results)
      (any (lambda (r) (and (pair? r) (eq? (car r) 'error))) results)))

;; Starts step number i of t as a task of its own.
(define (start-step t s i previous coordinator options)
  (apply start-task (task-name t) (length (step-procs s))
         (map (lambda (c) (if (same? c) (same-robot t c) c)) (step-capabilities s))
         (map (lambda (c m) (if (same? c) #f m))
              (step-capabilities s) (step-metrics s))
         (map (lambda (p)
                (sendable-lambda ()
                  (with-coordinator coordinator (lambda () (p previous)))))
              (step-procs s))
         (append (step-options s) options)))

;; The capabilities of the robot that (same J K) names: its uid, to
;; itself.
(define (same-robot t c)
  (let ((team (task-team (list-ref (task-steps t) (- (cadr c) 1)))))
    (if (> (car (cddr c)) (length team))
        (error "task-step: no such component" c))
    (list (list (list-ref team (- (car (cddr c)) 1))) '())))

;;; Tasks that wait their turn (thesis ch. 6; docs/tasks.md)
;;
;; A task started with wait #t that finds too few capable robots free
;; waits for them, holding nothing and trying only when a robot offers
;; itself, while its poser subscribes to waiting-tasks and tells the lab
;; that a task waits (note-waiters!).  When a robot's exclusive subjects
;; are freed (pubsub's on-free!), the robot asks waiting-tasks who waits
;; for it, and offers itself to each in rank order, its subjects kept for
;; that one's poser while it tries, until one starts or none can.  A rank
;; is (KEY POSED ID), KEY being the task's priority less aging times the
;; second it was posed: the higher KEY goes first, then the earlier
;; POSED, then the smaller ID.  That is a total order, the same in every
;; address space, and aging does not reorder the tasks that wait: it
;; raises all their priorities alike, and only a task posed later starts
;; from lower down.  A task no live robot of the lab is capable of fails
;; at once; one whose capable robots all die while it waits fails when
;; it next looks at the lab, every ten heartbeats or a third of the
;; lease, whichever is sooner.

(define-record-type turn
  (make-turn wait? hold? priority deadline posed)
  turn?
  (wait? turn-wait?)
  (hold? turn-hold?)
  (priority turn-priority)
  (deadline turn-deadline)              ; monotonic-seconds, or #f
  (posed turn-posed))                   ; utc-seconds

;; A turn from start-task's keywords and their values.
(define (read-turn who options)
  (let loop ((kv options)
             (wait (eq? (lab-setting (current-lab) 'when-robots-busy) 'wait))
             (hold #f)
             (priority (pose-task-priority))
             (deadline #f))
    (define (bad what)
      (error (string-append who ": " what) kv))
    (define (value ok? what)
      (if (not (ok? (cadr kv))) (bad what))
      (cadr kv))
    (define (at-least-0? x) (and (real? x) (>= x 0)))
    (cond
     ((null? kv)
      (make-turn (or wait hold) hold priority
                 (and deadline (+ (monotonic-seconds) deadline)) (utc-seconds)))
     ((not (and (symbol? (car kv)) (pair? (cdr kv))))
      (bad (string-append "after the lists come keywords, each with its value: "
                          "wait, hold, priority, deadline")))
     ((eq? (car kv) 'wait)
      (loop (cddr kv) (value boolean? "wait is #t or #f") hold priority deadline))
     ((eq? (car kv) 'hold)
      (loop (cddr kv) wait (value boolean? "hold is #t or #f") priority deadline))
     ((eq? (car kv) 'priority)
      (loop (cddr kv) wait hold (value at-least-0? "priority is a number, 0 or more")
            deadline))
     ((eq? (car kv) 'deadline)
      (loop (cddr kv) wait hold priority
            (value at-least-0? "deadline is a number of seconds, 0 or more")))
     (else (bad "no such option; the options are wait, hold, priority and deadline")))))

;; Refuses a task that would wait when this address space has
;; max-waiting tasks waiting or about to.  Under *tasks-lock*.
(define (check-waiting-room turn)
  (if (and turn (turn-wait? turn)
           (>= (count (lambda (t) (and (task-turn t) (turn-wait? (task-turn t))
                                       (memq (task-state t) '(negotiating waiting))))
                      *posed*)
               (lab-setting (current-lab) 'max-waiting)))
      (error "start-task: this address space has max-waiting tasks waiting already"
             (lab-setting (current-lab) 'max-waiting))))

(define (turn-rank turn id)
  (list (- (turn-priority turn) (* (lab-setting (current-lab) 'aging) (turn-posed turn)))
        (turn-posed turn) (symbol->string id)))

;; The parts of a rank, (SCORE POSED ID) as turn-rank makes it: it travels
;; to the other posers.
(define (rank-score r) (car r))
(define (rank-posed r) (cadr r))
(define (rank-id r) (car (cddr r)))

;; Whether rank a goes before rank b.
(define (rank<? a b)
  (or (> (rank-score a) (rank-score b))
      (and (= (rank-score a) (rank-score b))
           (or (< (rank-posed a) (rank-posed b))
               (and (= (rank-posed a) (rank-posed b))
                    (string<? (rank-id a) (rank-id b)))))))

;; A task waiting here: news is what came for it, offers and cancels, and
;; bell rings when news comes.
(define-record-type waiter
  (make-waiter task components rank)
  waiter?
  (task waiter-task)
  (components waiter-components)
  (rank waiter-rank)
  (held waiter-held waiter-held-set!)            ; ((INDEX WINNER TYPE) ...)
  (looked waiter-looked waiter-looked-set!)      ; monotonic-seconds
  (kept waiter-kept waiter-kept-set!)            ; monotonic-seconds
  (yielded waiter-yielded waiter-yielded-set!)   ; robots it gave way on
  (capable waiter-capable waiter-capable-set!)   ; uids of its capable robots, or #t
  (position waiter-position waiter-position-set!)
  (why waiter-why waiter-why-set!)               ; a line a component
  (news waiter-news waiter-news-set!)
  (bell waiter-bell waiter-bell-set!))

(define *waiters* '())

(define (enlist! w)
  (waiter-held-set! w '())
  (waiter-looked-set! w #f)
  (waiter-kept-set! w (monotonic-seconds))
  (waiter-yielded-set! w '())
  (waiter-capable-set! w #t)            ; any robot, until it has looked
  (waiter-position-set! w #f)
  (waiter-why-set! w '())
  (waiter-news-set! w '())
  (waiter-bell-set! w (make-mailbox))
  (with-lock *tasks-lock*
    (lambda ()
      (task-waiter-set! (waiter-task w) w)
      (set! *waiters* (cons w *waiters*))
      (subscribe 'waiting-tasks)))
  (guard (e (#t (log-warn "telling the lab a task waits: " (error-message e))))
    (publish 'all note-waiters!)))

;; The offers w had not answered are declined: a robot waits for no task
;; that no longer waits.
(define (delist! w)
  (with-lock *tasks-lock*
    (lambda ()
      (task-waiter-set! (waiter-task w) #f)
      (set! *waiters* (remove (lambda (x) (eq? x w)) *waiters*))
      (answer-offers! (filter offer? (waiter-news w)) #f)
      (waiter-news-set! w '())
      (if (null? *waiters*) (unsubscribe 'waiting-tasks)))))

;; A piece of news is (posed), (cancel), (give-way UID) or (offer REPLY
;; UID): its kind, then what it says, read by name.
(define (news-kind n) (car n))
(define (offer? n) (eq? (news-kind n) 'offer))
(define (offer-reply n) (cadr n))
(define (offer-uid n) (car (cddr n)))
(define (give-way-uid n) (cadr n))

(define (tell-waiter! w news)
  (with-lock *tasks-lock*
    (lambda ()
      (cond ((memq w *waiters*)
             (waiter-news-set! w (cons news (waiter-news w)))
             (mailbox-put! (waiter-bell w) #t))
            ((offer? news) (answer-offers! (list news) #f))))))

;; The news that came for w, oldest first, once some has come or the
;; monotonic second until has passed.
(define (take-news! w until)
  (mailbox-take (waiter-bell w) until (lambda () #f))
  (with-lock *tasks-lock*
    (lambda ()
      (let ((news (reverse (waiter-news w))))
        (waiter-news-set! w '())
        (waiter-bell-set! w (make-mailbox))
        news))))

;; What try, a procedure of the task's waiter that negotiates cs of t,
;; answers; for a task that waits, tried again whenever a robot it may
;; use is offered, until it wins its robots or cannot: (winners
;; type-list), or a symbol, not-enough-takers, deadline or cancelled.
(define (negotiate-turn t cs try)
  (let ((w (make-waiter t cs (turn-rank (task-turn t) (task-id t)))))
    (if (not (turn-wait? (task-turn t)))
        (try w)
        (dynamic-wind
         (lambda () (enlist! w))
         (lambda () (wait-turn w try '((posed))))
         (lambda () (let-go-held! w) (delist! w))))))

;; Tries, answers the offers that woke it, and waits for the next.  It
;; tries only when a robot offered itself, or when it was posed with no
;; better-ranked task waiting for a robot it may use: a robot's offers
;; come in rank order, and a try out of turn could take a robot freed for
;; a better-ranked task.  It looks at the lab again when what it holds
;; changed, or a second after its last look: an offer is answered by one
;; try.
(define (wait-turn w try news)
  (let ((t (waiter-task w))
        (offers (filter offer? news))
        (held (held-uids w)))
    (give-way! w news)
    (cond
     ((eq? (task-state t) 'cancelled) (answer-offers! offers #f) 'cancelled)
     ((let-go? t) (answer-offers! offers #f) 'let-go)
     ((past? (turn-deadline (task-turn t))) (answer-offers! offers #f) 'deadline)
     (else
      (let ((team (if (or (pair? offers)
                          (and (equal? news '((posed))) (not (behind-others? w))))
                      (try-in-turn w try (map offer-uid offers))
                      'not-enough-takers)))
        (answer-offers! offers (pair? team))
        (cond
         ((pair? team) team)
         ((and (or (not (equal? held (held-uids w))) (look-due? w)) (look! w))
          => (lambda (never)
               (for-each (lambda (c) (component-state-set! c (list 'failed never)))
                         (waiter-components w))
               'not-enough-takers))
         (else
          (if (> (- (monotonic-seconds) (waiter-kept w))
                 (/ (lab-setting (current-lab) 'lease) 4))
              (keep-held! w))
          (wait-turn w try
                     (take-news! w (next-look (turn-deadline (task-turn t))))))))))))

;; One try of w's, after the tries of this address space's other waiting
;; tasks: two at once, each offered a robot, each reserved the other's
;; robot as a candidate of its negotiation, and the one that lost its
;; robot so, for a moment, found none and declined it.  The robots offered
;; to the others are left alone, and so are all but those offered to w,
;; the uids offered, when w can take robots one at a time (it holds, or
;; needs one): a robot may be kept for this poser on its way to offer
;; itself to another of its tasks.
(define *try-lock* (make-mutex 'tries))

(define (try-in-turn w try offered)
  (with-lock *try-lock*
    (lambda ()
      (quiet-try (lambda ()
                   (parameterize ((pose-task-excluded (append (offered-to-others w)
                                                              (not-offered w offered)
                                                              (pose-task-excluded))))
                     (try w)))))))

(define (not-offered w offered)
  (let ((t (waiter-task w)))
    (if (and (pair? offered) (list? (waiter-capable w))
             (or (turn-hold? (task-turn t)) (= 1 (length (waiter-components w)))))
        (remove (lambda (uid) (memq uid offered)) (waiter-capable w))
        '())))

;;; Holding what it has (the thesis's chapter 6 wish)
;;
;; A task started with hold #t keeps, while it waits, the robots it won
;; for some of its components, and waits for the others.  No deadlock:
;; a waiting task gives up what it holds when a better-ranked waiting
;; task could start with it (give-way!), and ranks are totally ordered,
;; so the best-ranked waiting task never waits on one that holds; a
;; running component is never taken away.  docs/allocation.md gives the
;; argument.

;; A try that keeps what it wins: each component of w not yet held is
;; negotiated alone, in priority order, without the robots held or given
;; way on.  Answers (winners type-list) once every component has a robot.
(define (hold-try w priorities)
  (let ((t (waiter-task w)) (cs (waiter-components w)))
    (for-each
     (lambda (c)
       (if (not (assv (component-index c) (waiter-held w)))
           (let ((team (parameterize ((pose-task-excluded
                                       (append (held-uids w) (waiter-yielded w)
                                               (pose-task-excluded))))
                         (negotiate (task-name t) 1 (list (component-capabilities c))
                                    (list (component-metric c))
                                    (list (component-proc c))))))
             (if (pair? team)
                 (waiter-held-set! w (cons (list (component-index c)
                                                 (car (negotiated-winners team))
                                                 (car (negotiated-types team)))
                                           (waiter-held w)))))))
     (map cdr (list-sort (lambda (a b) (> (car a) (car b))) (map cons priorities cs))))
    (let ((held (map (lambda (c) (assv (component-index c) (waiter-held w))) cs)))
      (cond ((every pair? held)
             (waiter-held-set! w '())
             (list (map held-winner held) (map held-type held)))
            (else 'not-enough-takers)))))

;; What w holds of a component, (INDEX WINNER TYPE), read by name.
(define (held-index h) (car h))
(define (held-winner h) (cadr h))
(define (held-type h) (car (cddr h)))
(define (held-uid h) (winner-uid (held-winner h)))

(define (held-uids w) (map held-uid (waiter-held w)))

;; Frees what w holds on robot uid, or on every robot.
(define (let-go-held! w . uid)
  (let ((out (filter (lambda (h) (or (null? uid) (eq? (held-uid h) (car uid))))
                     (waiter-held w))))
    (for-each (lambda (h) (free-winner! (held-winner h) (held-type h))) out)
    (waiter-held-set! w (remove (lambda (h) (memq h out)) (waiter-held w)))))

;; Holds what w holds for another lease.
(define (keep-held! w)
  (waiter-kept-set! w (monotonic-seconds))
  (for-each (lambda (h)
              (if (eq? (held-type h) 'exclusive)
                  (if (not (guard (e (#t #f)) ((winner-promise (held-winner h)) 'keep)))
                      (let-go-held! w (held-uid h)))))
            (waiter-held w)))

;; Acts on the news: gives way on each robot a better-ranked task asked
;; for, and takes robots offered to it again.
(define (give-way! w news)
  (for-each
   (lambda (n)
     (case (news-kind n)
       ((give-way)
        (let ((uid (give-way-uid n)))
          (when (memq uid (held-uids w))
            (progress (task-id (waiter-task w)) ": gives way on " uid)
            (let-go-held! w uid)
            (waiter-yielded-set! w (cons uid (waiter-yielded w))))))
       ((offer)
        (waiter-yielded-set! w (remove (lambda (u) (eq? u (offer-uid n)))
                                       (waiter-yielded w))))))
   news))

;;> What a waiting task of rank \var{rank} calls where the task that holds
;;> robot \var{uid} waits: that task gives way on it if \var{rank} goes
;;> before its own.  Answers #t.
(define (receive-give-way uid rank)
  (for-each (lambda (w)
              (if (and (memq uid (held-uids w)) (rank<? rank (waiter-rank w)))
                  (tell-waiter! w (list 'give-way uid))))
            (with-lock *tasks-lock* (lambda () *waiters*)))
  #t)

;; Asks the waiting tasks that rank after w, and hold robots w could
;; start with, to give way, when with those robots and the free ones each
;; of w's components not held would have one.
(define (ask-way! w lines others)
  (let* ((worse (filter (lambda (o) (rank<? (waiter-rank w) (waiting-there-rank o)))
                        others))
         (yieldable (append-map waiting-there-held worse))
         (held (map held-index (waiter-held w)))
         (open (filter-map (lambda (c line)
                             (and (not (memv (component-index c) held))
                                  (filter (lambda (uid)
                                            (or (memq uid (explanation-free line))
                                                (memq uid yieldable)))
                                          (remove (lambda (u) (memq u (held-uids w)))
                                                  (explanation-capable line)))))
                           (waiter-components w) lines))
         (wanted (filter (lambda (uid) (memq uid yieldable)) (apply append open))))
    (when (and (pair? wanted) (every pair? open)
               (>= (length (delete-duplicates (apply append open))) (length open)))
      (for-each (lambda (o)
                  (for-each (lambda (uid)
                              (if (memq uid wanted)
                                  (guard (e (#t #f))
                                    (remote-apply (uid->aspace (waiting-there-poser o))
                                                  receive-give-way uid (waiter-rank w)))))
                            (waiting-there-held o)))
                worse))))

(define (look-due? w)
  (or (not (waiter-looked w)) (> (- (monotonic-seconds) (waiter-looked w)) 1)))

(define (past? deadline) (and deadline (>= (monotonic-seconds) deadline)))

(define (next-look deadline)
  (let ((look (+ (monotonic-seconds)
                 (min (* 10 (lab-setting (current-lab) 'heartbeat))
                      (/ (lab-setting (current-lab) 'lease) 3)))))
    (if deadline (min deadline look) look)))

;; A try that answers at once and writes no explanation: the waiter
;; gives its own.
(define (quiet-try try)
  (parameterize ((pose-task-retries 0) (current-error-port (open-output-string)))
    (try)))

(define (answer-offers! offers took?)
  (for-each (lambda (offer) (mailbox-put! (offer-reply offer) took?)) offers))

;; Looks at the lab for w after a try that failed: why it waits, and its
;; place in line, in its components' states; answers why it never can be
;; served, or #f.
(define (look! w)
  (waiter-looked-set! w (monotonic-seconds))
  (let* ((cs (waiter-components w))
         (lines (explain-components
                 (map (lambda (c) (capability-layout (component-capabilities c))) cs)))
         (capable (map (lambda (line)
                         (remove (lambda (uid) (memq uid (pose-task-excluded)))
                                 (explanation-capable line)))
                       lines))
         (others (guard (e (#t '())) (waiting-elsewhere)))
         (exclusive (filter-map (lambda (c caps)
                                  (and (pair? (car (capability-layout
                                                    (component-capabilities c))))
                                       caps))
                                cs capable)))
    (cond
     ((any null? capable)
      (string-append "no live robot of the lab is capable of it:"
                     (apply string-append (map explanation-line lines))))
     ((< (length (delete-duplicates (apply append exclusive))) (length exclusive))
      "fewer live robots of the lab are capable of it than it has components")
     (else
      (waiter-capable-set! w (delete-duplicates (apply append capable)))
      (remind-free! (delete-duplicates (append-map explanation-free lines)))
      (waiter-why-set! w (map (lambda (line) (trimmed (explanation-line line))) lines))
      (waiter-position-set! w (place-in-line w others))
      (ask-way! w lines others)
      (with-lock *tasks-lock*
        (lambda ()
          (if (eq? (task-state (waiter-task w)) 'negotiating)
              (task-state-set! (waiter-task w) 'waiting))))
      (for-each (lambda (c why)
                  (component-state-set! c (list 'waiting (waiter-position w) why)))
                cs (waiter-why w))
      (progress (task-id (waiter-task w)) ": waiting, " (waiter-position w)
                " in line")
      #f))))

;; Robots that a look finds free may have made their offers before this
;; task waited, or be making them: each is asked to offer itself (again),
;; best rank first, rather than taken by a try out of turn.
(define (remind-free! uids)
  (for-each (lambda (uid)
              (guard (e (#t (log-warn "reminding " uid ": " (error-message e))))
                (parameterize ((remote-timeout 1))
                  (remote-apply (uid->aspace uid) note-waiters!))))
            uids))

(define (trimmed line)
  (let loop ((s line))
    (cond ((and (> (string-length s) 0) (char-whitespace? (string-ref s 0)))
           (loop (substring s 1 (string-length s))))
          ((and (> (string-length s) 0)
                (char-whitespace? (string-ref s (- (string-length s) 1))))
           (loop (substring s 0 (- (string-length s) 1))))
          (else s))))

;; Brings w's place in line, in its components' states, up to date.
(define (move-up! w)
  (let ((place (guard (e (#t (waiter-position w)))
                 (place-in-line w (waiting-elsewhere)))))
    (waiter-position-set! w place)
    (for-each (lambda (c)
                (let ((state (component-state c)))
                  (if (eq? (car state) 'waiting)
                      (component-state-set! c (list 'waiting place (car (cddr state)))))))
              (waiter-components w))))

;; Whether a better-ranked task of the lab waits for a robot w may use.
(define (behind-others? w)
  (> (place-in-line w (guard (e (#t '())) (waiting-elsewhere))) 1))

;; w's place among the tasks of the lab that wait for a robot it may use:
;; 1 + how many of them rank before it.
(define (place-in-line w others)
  (+ 1 (count (lambda (other)
                (and (rank<? (waiting-there-rank other) (waiter-rank w))
                     (may-use? other (waiter-capable w))))
              others)))

;; Whether other, a waiting-there, may use one of uids.
(define (may-use? other uids)
  (or (eq? (waiting-there-capable other) #t) (eq? uids #t)
      (any (lambda (uid) (memq uid (waiting-there-capable other))) uids)))

;;> The (RANK CAPABLE HELD) of each task waiting here: its rank, the uids
;;> of the robots it may use (#t before it has looked), and of those it
;;> holds.
(define (waiting-ranks)
  (map (lambda (w) (list (waiter-rank w) (waiter-capable w) (held-uids w)))
       (with-lock *tasks-lock* (lambda () *waiters*))))

;; A task that waits at poser, as its entry of waiting-ranks says.
(define-record-type waiting-there
  (make-waiting-there poser rank capable held)
  waiting-there?
  (poser waiting-there-poser)
  (rank waiting-there-rank)
  (capable waiting-there-capable)
  (held waiting-there-held))

;; Every task of the lab that waits, each a waiting-there; request
;; answers (POSER ENTRIES) for each poser.
(define (waiting-elsewhere)
  (append-map (lambda (answer)
                (map (lambda (e) (apply make-waiting-there (car answer) e))
                     (cadr answer)))
              (request 'waiting-tasks waiting-ranks)))

;;> The (RANK POSER ID) of each task waiting here that may use robot
;;> \var{uid}.
(define (waiting-for uid)
  (filter-map (lambda (w)
                (and (or (eq? (waiter-capable w) #t) (memq uid (waiter-capable w)))
                     (list (waiter-rank w) (local-aspace-uid) (task-id (waiter-task w)))))
              (with-lock *tasks-lock* (lambda () *waiters*))))

;; The parts of an entry of waiting-for, from any poser of the lab.
(define (wanting-rank e) (car e))
(define (wanting-poser e) (cadr e))
(define (wanting-id e) (car (cddr e)))

;;> What a freed robot \var{uid} calls where task \var{id} waits: the
;;> task tries again at once; answers whether it started, #f when it is
;;> no longer waiting here, is already offered a robot for each component
;;> it does not hold, or did not answer within two seconds.
(define (receive-offer id uid)
  (let* ((reply (make-mailbox))
         (offer (cons uid id))
         (w (with-lock *tasks-lock*
              (lambda ()
                (let ((w (find (lambda (w) (eq? (task-id (waiter-task w)) id))
                               *waiters*)))
                  (and w (not (offered-enough? w))
                       (begin (set! *offers* (cons offer *offers*)) w)))))))
    (and w
         (dynamic-wind
          (lambda () #f)
          (lambda ()
            (tell-waiter! w (list 'offer reply uid))
            (mailbox-take reply (+ (monotonic-seconds) 2) (lambda () #f)))
          (lambda ()
            (with-lock *tasks-lock*
              (lambda ()
                (set! *offers* (remove (lambda (o) (eq? o offer)) *offers*)))))))))

;; Whether w is offered a robot for each component it does not hold: two
;; robots freed together offer themselves to one task, and the second
;; goes on to the next task at once rather than after the first's try.
;; A robot that w won, holding, in the try its offer began is no longer
;; one of them, though its offer is answered only when that try ends.
;; Under *tasks-lock*.
(define (offered-enough? w)
  (let ((id (task-id (waiter-task w))) (held (held-uids w)))
    (>= (count (lambda (o) (and (eq? (cdr o) id) (not (memq (car o) held)))) *offers*)
        (- (length (waiter-components w)) (length held)))))

;; The offers being answered here, (UID . ID): the robot UID keeps itself
;; for this poser while task ID tries, and the poser's other waiting
;; tasks leave it alone meanwhile.
(define *offers* '())

(define (offered-to-others w)
  (let ((id (task-id (waiter-task w))))
    (filter-map (lambda (o) (and (not (eq? (cdr o) id)) (car o)))
                (with-lock *tasks-lock* (lambda () *offers*)))))

;;; The robot's side: offers when its subjects are freed

(define *offering* #f)                  ; an offer round runs here
(define *offer-again* #f)               ; and another was asked for meanwhile
(define *offer-lock* (make-mutex 'offers))

;; Whether a task may wait for this robot: set when a task starts to
;; wait anywhere, cleared by an offer round that finds none, so that a lab
;; where no task waits sends nothing more when a robot is freed.
(define *waiters-here?* #f)

;;> What a poser publishes to the lab when one of its tasks starts to
;;> wait: the robots offer themselves when freed, and a free robot at
;;> once, since a task posed behind others waits for the offers.
(define (note-waiters!)
  (set! *waiters-here?* #t)
  (set! *new-waiters* #t)
  (if (and (robot-here?) (free-here?)) (robot-freed!)))

;; Whether a task started to wait, or was reminded of, since this robot's
;; offer round asked who waits: the round's list may lack a better-ranked
;; task, and it asks again before its next offer (forty tasks posed at
;; once: a round that had asked before the best of them waited went on
;; down its list to a worse one).
(define *new-waiters* #f)

(define (robot-here?)
  (let ((a (lab-aspace-by-uid (current-lab) (local-aspace-uid))))
    (and a (lab-aspace-clause a 'capabilities) #t)))

;; Runs on every freeing of exclusive subjects here (pubsub's on-free!):
;; starts an offer round, or asks the one running for another.  A round
;; that runs keeps the robot as it is: offered to a poser, a runner-up of
;; that poser's negotiation is freed while the robot waits for its answer,
;; and the task that tries must still find the robot its poser's.
(define (robot-freed!)
  (when (and *waiters-here?*
             (with-lock *offer-lock*
               (lambda ()
                 (if *offering*
                     (begin (set! *offer-again* #t) #f)
                     (begin (set! *offering* #t) #t)))))
    ;; At once, not in the round's thread, which may start late.
    (if *waiters-seen* (offer-subjects! 'nobody 3))
    (thread-start! (make-logged-thread offer-rounds 'offers))))

;; The robot is kept for the poser it was last offered to until the
;; rounds end, so that no task takes it between two rounds.
(define (offer-rounds)
  (guard (e (#t (log-warn "offering this robot: " (error-message e))))
    (offer-round))
  (if (with-lock *offer-lock*
        (lambda ()
          (let ((again *offer-again*))
            (set! *offer-again* #f)
            (when (not again)
              (offer-subjects! #f)
              (set! *offering* #f))
            again)))
      (offer-rounds)))

;; Offers this robot, while it is free, to the tasks that wait for it,
;; best rank first.  While one tries, only its poser may reserve here;
;; while it asks who waits, if tasks waited at its last round, nobody may,
;; so that no task takes it before the best-ranked has been offered it.
;; In a lab where no task waits it refuses nobody, as in the thesis.
(define *waiters-seen* #f)

(define (offer-round)
  (let ((me (local-aspace-uid)))
    (set! *waiters-here?* #f)       ; before asking: a note after it stands
    (set! *new-waiters* #f)
    (offer-subjects! (and *waiters-seen* 'nobody) 3)
    (let ((waiting (list-sort (lambda (a b) (rank<? (wanting-rank a) (wanting-rank b)))
                              (guard (e (#t '()))
                                (append-map cadr (request 'waiting-tasks
                                                          waiting-for me))))))
      (set! *waiters-seen* (pair? waiting))
      (if (pair? waiting) (set! *waiters-here?* #t))
      (offer-to me waiting))))

(define (offer-to me waiting)
  (when (and (pair? waiting) (free-here?))
    (let ((poser (wanting-poser (car waiting))))
      (offer-subjects! poser 3)
      (guard (e (#t #f))
        (parameterize ((remote-timeout 3))
          (remote-apply (uid->aspace poser) receive-offer
                        (wanting-id (car waiting)) me)))
      (if (and *new-waiters* (free-here?))
          (with-lock *offer-lock* (lambda () (set! *offer-again* #t)))
          (offer-to me (cdr waiting))))))

;; Whether no subject here is held exclusively.
(define (free-here?)
  (every (lambda (s) (memq (cadr s) '(() shared))) (subscription-statuses '>)))

(on-free! robot-freed!)
