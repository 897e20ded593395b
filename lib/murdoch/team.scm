;;;; MOVER's dynamic teams (thesis §3.3.3): with-team and on-list.

;;> The robots of the team being run.
(define current-team (make-parameter '()))
(sandbox-parameter! current-team)

;;> Runs \var{body} with \var{uids} as the current team.
(define-syntax with-team
  (syntax-rules ()
    ((with-team uids body ...)
     (parameterize ((current-team uids)) body ...))))

;;> Runs each procedure of \var{procs} on a robot of the team, all at once,
;;> with MOVER's options: (fixed UIDS) pairs the procedures with UIDS;
;;> (all) with the whole team; (arbitrary N [from UIDS]) with N picked at
;;> random; (timeout SECONDS), 0 for (task-timeout); (collect PROC) to
;;> combine the results (default: the list, in order); (on-error PROC),
;;> applied to the uid and the error, whose value stands for the result;
;;> (debug #t) to tell each start and end.
(define-syntax on-list
  (syntax-rules ()
    ((on-list (option ...) procs)
     (exec-on (list (on-list-option option) ...) procs))))

(define-syntax on-list-option
  (syntax-rules (from)
    ((_ (arbitrary n from uids)) (list 'arbitrary n uids))
    ((_ (key arg ...)) (list 'key arg ...))))

(define (option options key default)
  (cond ((assq key options) => cadr) (else default)))

;; Macros are defined before their first use, which Chibi requires.
;;> A thunk that runs the task's components on its chosen robots, as a
;;> team: an exclusive component by applying its winner's promise to #t, a
;;> non-exclusive one by running its procedure on the winner.
(define (with-team-proc-maker task-uids type-list procs)
  (let ((proclist (map (lambda (task-uid proc type)
                         (if (eq? type 'exclusive)
                             (let ((promise (cadr task-uid)))
                               (sendable-lambda () (promise #t)))
                             proc))
                       task-uids procs type-list))
        (uids (map car task-uids)))
    (lambda ()
      (with-team uids
        (on-list ((fixed uids)) proclist)))))

;;> Seconds a component may run before its caller gives up on it, when
;;> on-list is not given a timeout: pose-task's components, for one.  The
;;> component is told as failed (see on-error), and stops on its robot at
;;> its next robot command or remote call (abandon.scm); until then an
;;> exclusive one holds its subjects.
(define task-timeout (make-parameter 600))
(sandbox-parameter! task-timeout)

(define (select-robots options)
  (cond
   ((assq 'fixed options) => cadr)
   ((assq 'arbitrary options)
    => (lambda (o)
         (let ((pool (shuffle (if (pair? (cddr o)) (car (cddr o)) (current-team)))))
           (take pool (min (cadr o) (length pool))))))
   (else (current-team))))


(define (exec-on options procs)
  (let* ((uids (select-robots options))
         (seconds (let ((s (option options 'timeout 0)))
                    (if (and (number? s) (positive? s)) s (task-timeout))))
         (on-error (option options 'on-error team-error))
         (collect (option options 'collect list))
         (debug? (option options 'debug #f))
         (port (pose-task-progress)))   ; threads do not inherit parameters
    (if (not (= (length uids) (length procs)))
        (error "on-list: the team and the procedures do not pair up"
               uids (length procs)))
    (apply collect
           (join-or-interrupt
            (map (lambda (uid proc)
                   (thread-start!
                    (make-thread
                     (lambda ()
                       (parameterize ((pose-task-progress port))
                         (run-on uid proc seconds on-error debug?))))))
                 uids procs)))))

;; The threads' results, in order.  Left before they are all done (Ctrl-C
;; at the REPL interrupts the join), the threads are interrupted too: each
;; gives up its component, which stops on its robot (abandon.scm).
(define (join-or-interrupt threads)
  (undo-on-raise (lambda () (for-each thread-interrupt! threads))
                 (lambda () (map thread-join! threads))))

;; Runs one component on its robot; an error or a timeout goes to on-error.
(define (run-on uid proc seconds on-error debug?)
  (if debug? (progress "  " uid " starts"))
  (let ((result (guard (e (#t (on-error uid e)))
                  (if (eq? uid (local-aspace-uid))
                      (apply-here-by proc seconds)
                      (parameterize ((remote-timeout seconds))
                        (remote-apply (uid->aspace uid) proc))))))
    (if debug? (progress "  " uid " done: " result))
    result))

;; A component that this address space won runs here, in a thread of its
;; own, so that seconds bound it as they bound one elsewhere: the wait
;; ends, by timeout or interrupt, and the component is given up
;; (abandon.scm).
(define (apply-here-by proc seconds)
  (let* ((outcome #f)
         (runner (make-thread
                  (lambda ()
                    (set! outcome
                          (guard (e (#t (cons 'raised e)))
                            (cons 'value (remote-apply (local-aspace) proc))))))))
    (thread-start! runner)
    (dynamic-wind (lambda () #f)
                  (lambda () (thread-join! runner seconds #f))
                  (lambda () (if (not outcome) (abandon-thread! runner))))
    (cond ((not outcome)
           (error (string-append "no answer within " (number->string seconds) " s")))
          ((eq? (car outcome) 'raised) (raise (cdr outcome)))
          (else (cdr outcome)))))

;; The default on-error: tell, and let (error UID MESSAGE) stand for the
;; result, so the other components' results still come back.
(define (team-error uid e)
  (let ((message (if (remote-error? e)
                     (remote-error-message e)
                     (if (error-object? e) (error-object-message e) e))))
    (log-warn "component on " uid " failed: " message)
    (list 'error uid message)))

;;; What the thesis's task procedures call

;;> The procedure that answers #t, as the thesis's tasks use it.
(define (t) #t)

;;> Sorts \var{ls} by \var{less?} (the thesis's sort-list).
(define (sort-list ls less?) (list-sort less? ls))

;;> A thunk answering random integers from 0 below \var{n}.
(define (make-maxrandom n) (lambda () (random-integer n)))
