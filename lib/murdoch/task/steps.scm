;;;; Tasks of several steps (thesis ch. 6: pose-task with MOVER's
;;;; synchronization)
;;
;; A step starts when the step before is done, its procedures applied to
;; that step's results; a component may ask for an earlier step's robot
;; (team.scm).  A step with a failed component stops the task.

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

;;> The parts of a step made by task-step, as they travel: its
;;> capabilities, metrics, procedures and options, task-step's arguments.
(define (step-parts s)
  (cons* (step-capabilities s) (step-metrics s) (step-procs s) (step-options s)))

;;> Starts a task of \var{steps} (made by task-step) and answers its task
;;> record at once; start-task's keywords may follow the steps, and each
;;> step is started with them.  task-status gives (step I STATUS) per step
;;> started, task-wait each step's results.
(define (start-steps task-name . steps+options)
  (let ((steps (take-while step? steps+options))
        (options (drop-while step? steps+options)))
    (if (not (and (symbol? task-name) (pair? steps)))
        (error "start-steps: a task name, then one or more steps made by task-step"))
    (read-turn "start-steps" options)
    (for-each check-same steps (iota (length steps) 1))
    (let ((t (new-task ((task-id-maker) task-name) task-name '() '() '() '() #f)))
      (go-steps! t steps options (lambda (i id args) #f))
      t)))

;;> Goes on with the task of steps \var{id}, a detached one taken over
;;> (detached.scm), as start-steps started it; answers its new task
;;> record at once.  \var{adopt-step} answers a step's record for one
;;> that started or ended before, or #f for one to start.
(define (resume-steps id task-name steps options adopt-step)
  (let ((t (new-task id task-name '() '() '() '() #f)))
    (go-steps! t steps options adopt-step)
    t))

(define (go-steps! t steps options adopt-step)
  (task-steps-set! t '())
  (let ((keeper (team-keeper)))
    (thread-start!
     (make-logged-thread
      (inheriting (lambda () (run-steps t steps options adopt-step keeper)))
      (task-id t)))))

;;> How the teams of the tasks of steps started under it outlive the
;;> address space that coordinates them: #f, or a procedure that (KEEPER
;;> TASK-ID TEAM-ID) answers the state kept for a step's team, or #f, and
;;> (KEEPER TASK-ID TEAM-ID STATE) keeps it (standby.scm's keep-team).
(define team-keeper (make-parameter #f))

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

(define (run-steps t steps options adopt-step keeper)
  (let loop ((i 1) (steps steps) (previous '()) (results '()))
    (cond
     ((let-go? t) #f)
     ((or (null? steps) (eq? (task-state t) 'cancelled))
      (finish! t (reverse results)))
     (else
      (let* ((sub #f)
             (coordinator (step-coordinator t i (lambda () sub) keeper))
             (step-results
              (begin
                (set! sub (begin-step t (car steps) i previous coordinator options
                                      adopt-step))
                (task-steps-set! t (append (task-steps t) (list sub)))
                ;; Let go while the step began: it lets the step go too.
                (if (let-go? t) (let-task-go! sub))
                (task-wait sub))))
        (release-coordinator! coordinator)
        (if (not (let-go? t)) (progress (task-id t) ": step " i " done: " step-results))
        (cond
         ((let-go? t) #f)
         ((step-failed? step-results)
          (when (not (eq? (task-state t) 'cancelled))
            (task-state-set! t (if (memq (task-state sub) '(cancelled deadline))
                                   (task-state sub)
                                   'failed))
            (task-why-set! t (task-why sub)))
          (finish! t (reverse (cons step-results results))))
         (else
          (loop (+ i 1) (cdr steps) step-results (cons step-results results)))))))))

(define (step-failed? results)
  (or (symbol? results)
      (any (lambda (r) (and (pair? r) (eq? (car r) 'error))) results)))

;; The coordinator of step i's team, under the step's id, acted for while
;; t is not let go, kept by keeper.
(define (step-coordinator t i sub keeper)
  (let ((id (step-task-id (task-id t) i)))
    (make-coordinator id
                      (lambda () (if (sub) (task-team (sub)) '()))
                      (lambda () (not (let-go? t)))
                      (and keeper
                           (lambda state (apply keeper (task-id t) id state))))))

;; Starts step number i of t as a task of its own, or has adopt-step
;; adopt it.
(define (begin-step t s i previous coordinator options adopt-step)
  (let ((id (step-task-id (task-id t) i))
        (args (cons* (task-name t) (length (step-procs s))
                     (map (lambda (c) (if (same? c) (same-robot t c) c))
                          (step-capabilities s))
                     (map (lambda (c m) (if (same? c) #f m))
                          (step-capabilities s) (step-metrics s))
                     (map (lambda (p)
                            (sendable-lambda ()
                              (with-coordinator coordinator (lambda () (p previous)))))
                          (step-procs s))
                     (append (step-options s) options))))
    (or (adopt-step i id args)
        (parameterize ((task-id-maker (lambda (name) id)))
          (apply start-task args)))))

;;> The id of step \var{i} of the task of steps \var{id}: ID.I, so that
;;> a coordinator that takes a detached task of steps over finds the
;;> step's components by it.
(define (step-task-id id i)
  (string->symbol (string-append (symbol->string id) "." (number->string i))))

;; The capabilities of the robot that (same J K) names: its uid, to
;; itself.
(define (same-robot t c)
  (let ((team (task-team (list-ref (task-steps t) (- (cadr c) 1)))))
    (if (> (car (cddr c)) (length team))
        (error "task-step: no such component" c))
    (list (list (list-ref team (- (car (cddr c)) 1))) '())))

