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
  ;;> A task's state, one word: negotiating, waiting, holding (it holds
  ;;> robots for some of its components and waits for the others),
  ;;> running, and once it is over done (every component completed),
  ;;> failed (task-why says why), cancelled or deadline.
  (state task-state task-state-set!)
  ;;> Why a failed task failed, its first failure's why (a string), else #f.
  (why task-why task-why-set!)
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
  ;; (negotiating), (waiting POSITION WHY), (holding UID), (running UID
  ;; SINCE), (done VALUE), (failed WHY), (cancelled), (deadline) or
  ;; (reassigned FROM TO); SINCE is a (utc-seconds).
  (state component-state component-state-set!)
  (attempts component-attempts component-attempts-set!)) ; ((UID . OUTCOME) ...)

;; The node's posed part: the tasks started here, newest first, those not
;; over and at most tasks-kept of those over; peers' calls find them by
;; name.  Its lock guards these lists and the tasks' and waiters' fields.
(define-record-type posed
  (make-posed list lock)
  posed?
  (list posed-list posed-list-set!)
  (lock posed-lock))

(define-syntax the-posed (syntax-rules () ((_) (node-posed *node*))))

(define (open-posed!) (node-posed-set! (this-node) (make-posed '() (make-mutex 'tasks))))

(define (tasks-lock) (posed-lock (the-posed)))

(define (posed-tasks) (posed-list (the-posed)))

(define (over? t) (memq (task-state t) '(done failed cancelled deadline)))

;; Under (tasks-lock).
(define (add-posed! t) (posed-list-set! (the-posed) (cons t (posed-list (the-posed)))))

;; Forgets the tasks over but the newest kept of them.  Under (tasks-lock).
(define (forget-over! kept)
  (let loop ((ts (posed-list (the-posed))) (n 0) (out '()))
    (cond ((null? ts) (posed-list-set! (the-posed) (reverse out)))
          ((not (over? (car ts))) (loop (cdr ts) n (cons (car ts) out)))
          ((< n kept) (loop (cdr ts) (+ n 1) (cons (car ts) out)))
          (else (loop (cdr ts) n out)))))

(define (fail-component! t c why)
  (component-state-set! c (list 'failed why))
  (if (not (task-why t)) (task-why-set! t why)))

;; A component's result, as pose-task gives it: its value, or (error UID
;; WHY) with the last robot it had, WHY "cancelled" or "deadline" for a
;; component of a task that was.
(define (component-result c)
  (let ((state (component-state c)))
    (if (eq? (car state) 'done)
        (cadr state)
        (list 'error (let ((attempts (component-attempts c)))
                       (and (pair? attempts) (car (last attempts))))
              (if (pair? (cdr state)) (cadr state) (symbol->string (car state)))))))

;;> The component's number in \var{s}, an entry of task-status.
(define (status-index s) (car s))

;;> The component's state in \var{s}, an entry of task-status:
;;> (negotiating), (waiting PLACE WHY), (holding UID), (running UID
;;> SINCE), (done VALUE), (failed WHY) ...
(define (status-state s) (cadr s))

;;> The (UID . OUTCOME) of each robot done with the component in \var{s}.
(define (status-attempts s) (car (cddr s)))

;;> Whether \var{s}, an entry of task-status, is a step's (step I
;;> STATUS), as a task of steps gives.
(define (step-status? s) (eq? (car s) 'step))

;;> The number I of the step in \var{s}, a step's entry of task-status.
(define (step-status-index s) (cadr s))

;;> The STATUS in \var{s}, a step's entry of task-status: the step's own
;;> task-status.
(define (step-status-entries s) (car (cddr s)))

(define (check-task-record who x)
  (if (not (task? x))
      (error (string-append who ": not a task; start-task answers one") x)))

;;> Whether \var{e}, an entry of (tasks), is a task started here.
(define (listed-posed? e) (eq? (car e) 'posed))

;;> The task id of \var{e}, an entry of (tasks).
(define (listed-id e) (cadr e))

;;> The state of \var{e}, a posed entry of (tasks): a word, as
;;> task-state's: waiting, holding, running, done, failed ...
(define (listed-state e) (car (cddr e)))

;;> Why \var{e}, a posed entry of (tasks), failed (a string) or waits (a
;;> string for each component: who holds the robots it could use); else #f.
(define (listed-why e) (list-ref e 3))

;;> The place in line of \var{e}, a posed entry of (tasks), when it
;;> waits or holds, else #f: 1 for the lab's best-ranked waiting task.
(define (listed-place e) (list-ref e 4))

;;> The priority of \var{e}, a posed entry of (tasks).
(define (listed-priority e) (list-ref e 5))

;;> The robots that \var{e}, a posed entry of (tasks) that holds, holds.
(define (listed-held e) (list-ref e 6))

;;> What \var{e}, a posed entry of (tasks) that waits or holds, still
;;> waits for.
(define (listed-wants e) (list-ref e 7))

;;> The component's number in \var{e}, a running entry of (tasks).
(define (listed-index e) (car (cddr e)))

;;> The poser of the component in \var{e}, a running entry of (tasks).
(define (listed-poser e) (cadr (cddr e)))
