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
;;> team; with \var{listed}, each runs as the procedure listed answers.
(define (with-team-proc-maker task-uids type-list procs . listed)
  (let* ((as (if (pair? listed) (car listed) (lambda (k proc) proc)))
         (proclist (map (lambda (k task-uid proc type)
                          (as k (if (eq? type 'exclusive)
                                    (let ((promise (cadr task-uid)))
                                      (sendable-lambda () (promise #t)))
                                    proc)))
                        (iota (length procs) 1) task-uids procs type-list))
         (uids (map car task-uids)))
    (lambda ()
      (with-team uids
        (on-list ((fixed uids)) proclist)))))

;;> Seconds a component may run before its caller gives up on it, when
;;> on-list is not given a timeout; it stops on its robot at its next
;;> command (abandon.scm).
(define task-timeout (make-parameter (lab-default 'task-timeout)))
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
                    (make-logged-thread
                     (lambda ()
                       (parameterize ((pose-task-progress port))
                         (run-on uid proc seconds on-error debug?))))))
                 uids procs)))))

;; The threads' results, in order; left early (Ctrl-C), the threads are
;; interrupted too and each gives up its component (abandon.scm).
(define (join-or-interrupt threads)
  (undo-on-raise (lambda () (for-each thread-interrupt! threads))
                 (lambda () (map thread-join! threads))))

(define (run-on uid proc seconds on-error debug?)
  (if debug? (progress "  " uid " starts"))
  (let ((result (guard (e (#t (on-error uid e)))
                  (if (eq? uid (local-aspace-uid))
                      (apply-here-by proc seconds)
                      (parameterize ((remote-timeout seconds))
                        (remote-apply (uid->aspace uid) proc))))))
    (if debug? (progress "  " uid " done: " result))
    result))

;; A component this address space won runs in a thread of its own, so
;; seconds bound it as they bound one elsewhere (abandon.scm).
(define (apply-here-by proc seconds)
  (let* ((outcome #f)
         (runner (make-logged-thread
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

;; The default on-error: tell, and let (error UID WHY) stand for the
;; result, so the other components' results still come back.
(define (team-error uid e)
  (let ((why (error-message e)))
    (log-warn "component on " uid " failed: " why)
    (list 'error uid why)))

;;; Synchronization inside a team, MOVER's way
;;
;; Members wait at named barriers and pass values by uid through the
;; team's coordinator, a proxy (encap) made where the task was posed;
;; with-coordinator lets a member find it wherever it runs.

;; The coordinator of the team being run here, or #f.
(define current-coordinator (make-parameter #f))
(sandbox-parameter! current-coordinator)

;;> Runs \var{thunk} as a member of the team whose coordinator is
;;> \var{coordinator}: team-barrier, team-send! and team-receive reach it,
;;> and current-team is its robots.
(define (with-coordinator coordinator thunk)
  (parameterize ((current-coordinator coordinator)
                 (current-team (coordinator 'team)))
    (thunk)))

;;> The step's robots as they are now, in component order, a lost member
;;> replaced; (current-team) keeps those it started with.
(define (step-team) ((team-coordinator "step-team") 'team))

(define (team-coordinator who)
  (or (current-coordinator)
      (error (string-append who ": not inside a team's step"))))

;;> Waits until every member of the current team has come to the barrier
;;> \var{name}, at most \var{seconds} (default: (task-timeout)); raises an
;;> error naming the members that did not come, when they run out.
(define (team-barrier name . seconds)
  (let ((s (if (pair? seconds) (car seconds) (task-timeout)))
        (c (team-coordinator "team-barrier")))
    (parameterize ((remote-timeout (+ s 1)))
      (let ((missing (c 'arrive name (local-aspace-uid) s)))
        (if (pair? missing)
            (error (string-append "team-barrier " (symbol->string name)
                                  ": timed out waiting for")
                   missing))
        #t))))

;;> Sends \var{value} to the member \var{uid} of the current team.
(define (team-send! uid value)
  ((team-coordinator "team-send!") 'send uid (local-aspace-uid) value)
  #t)

;;> The next value a member sent to this one, as (FROM . VALUE), waiting at
;;> most \var{seconds} (default: (task-timeout)); raises an error when none
;;> comes in time.
(define (team-receive . seconds)
  (let ((s (if (pair? seconds) (car seconds) (task-timeout)))
        (c (team-coordinator "team-receive")))
    (parameterize ((remote-timeout (+ s 1)))
      (or (c 'receive (local-aspace-uid) s)
          (error "team-receive: nothing came within" s)))))

(define-record-type letter
  (make-letter to from value)
  letter?
  (to letter-to)
  (from letter-from)
  (value letter-value))

;;> A coordinator for a team, as a proxy: (COORDINATOR 'team) is its
;;> robots, which \var{team-of} answers, once they are chosen.  Release it
;;> with release-proxy! when the team is done.
(define (make-coordinator team-of)
  (let ((arrived '()) (inboxes '())
        (lock (make-mutex 'team)) (changed (make-condition-variable 'team)))
    (define (wait-until done? seconds)
      (let ((deadline (+ (monotonic-seconds) seconds)))
        (let loop ()
          (mutex-lock! lock)
          (cond ((done?) => (lambda (x) (mutex-unlock! lock) x))
                ((and (< (monotonic-seconds) deadline)
                      (mutex-unlock! lock changed (seconds-until deadline)))
                 (loop))
                (else (mutex-unlock! lock) #f)))))
    (define (change! thunk)
      (with-lock lock thunk)
      (condition-variable-broadcast! changed))
    (define (arrive name uid seconds)
      (let ((missing (lambda ()
                       (remove (lambda (u) (member (cons name u) arrived))
                               (team-of)))))
        (change! (lambda () (set! arrived (cons (cons name uid) arrived))))
        (if (wait-until (lambda () (null? (missing))) seconds)
            '()
            (with-lock lock missing))))
    (define (send to from value)
      (change! (lambda ()
                 (set! inboxes (append inboxes (list (make-letter to from value)))))))
    (define (receive uid seconds)
      (wait-until (lambda ()
                    (let ((m (find (lambda (m) (eq? (letter-to m) uid)) inboxes)))
                      (and m (begin (set! inboxes (remove (lambda (x) (eq? x m)) inboxes))
                                    (cons (letter-from m) (letter-value m))))))
                  seconds))
    (encap (lambda (op . args)
             (case op
               ((team) (team-of))
               ((arrive) (apply arrive args))
               ((send) (apply send args))
               ((receive) (apply receive args))
               (else (error "a coordinator does not know" op)))))))

;;; What the thesis's task procedures call

;;> The procedure that answers #t, as the thesis's tasks use it.
(define (t) #t)

;;> Sorts \var{ls} by \var{less?} (the thesis's sort-list).
(define (sort-list ls less?) (list-sort less? ls))

;;> A thunk answering random integers from 0 below \var{n}.
(define (make-maxrandom n) (lambda () (random-integer n)))
