;;;; The task record: a task started here and its components, as the
;;;; life cycle (life-cycle.scm) keeps them, and the readers of what
;;;; task-status and (tasks) answer.

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
  (waiter task-waiter task-waiter-set!)  ; while it waits, its waiter record
  (acted task-acted task-acted-set!))   ; utc-seconds of its last heartbeat sent

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

;; The tasks started here, newest first.  Global, as the waiting tasks
;; (rank.scm) and the offers (offers.scm) are: peers' calls find them by
;; name.  The lock guards these lists and the tasks' and waiters' fields.
(define *posed* '())
(define *tasks-lock* (make-mutex 'tasks))

(define (posed-tasks) *posed*)

;; Under *tasks-lock*.
(define (add-posed! t) (set! *posed* (cons t *posed*)))
;; A component's result, as pose-task gives it: its value, or (error UID
;; WHY) with the last robot it had.
(define (component-result c)
  (let ((state (component-state c)))
    (if (eq? (car state) 'done)
        (cadr state)
        (list 'error (let ((attempts (component-attempts c)))
                       (and (pair? attempts) (car (last attempts))))
              (cadr state)))))

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
(define (check-task-record who x)
  (if (not (task? x))
      (error (string-append who ": not a task; start-task answers one") x)))


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
