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
;;> command (code/abandon.scm).
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
;; interrupted too and each gives up its component (code/abandon.scm).
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
;; seconds bound it as they bound one elsewhere (code/abandon.scm).
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
;; team's coordinator, held under the team's id where the task is
;; coordinated, and reached by its address, (ID UID KEPT?).  A member of
;; a kept team (a detached task's) whose UID is lost asks the lab-tasks
;; subject who holds ID now and calls again there, so any call may count
;; twice: an arrival counts once, a letter carries its sender's key and
;; is kept and taken once, and stays until the member's next receive
;; says it came.  A kept coordinator keeps each before its member hears.

;; What a member of a team keeps, in the thread running its procedure.
(define-record-type teammate
  (make-teammate id uid kept? nonce sent taken seen)
  teammate?
  (id teammate-id)
  (uid teammate-uid teammate-uid-set!)       ; where its coordinator is held
  (kept? teammate-kept?)                     ; whether it may be held elsewhere later
  (nonce teammate-nonce)                     ; its letters' keys: (UID NONCE N)
  (sent teammate-sent teammate-sent-set!)    ; letters sent so far
  (taken teammate-taken teammate-taken-set!) ; the last letter's key, or #f
  (seen teammate-seen teammate-seen-set!))   ; the keys of the letters taken

;; The member of the team being run here, or #f.
(define current-teammate (make-parameter #f))
(sandbox-parameter! current-teammate)

;;> Runs \var{thunk} as a member of the team whose coordinator is at
;;> \var{coordinator}, what make-coordinator answered: team-barrier,
;;> team-send! and team-receive reach it, and current-team is its robots.
(define (with-coordinator coordinator thunk)
  (let ((m (make-teammate (address-id coordinator) (address-uid coordinator)
                          (address-kept? coordinator)
                          (random-integer 1000000000) 0 #f '())))
    (parameterize ((current-teammate m)
                   (current-team (ask-team m "with-coordinator" 'team
                                           (lambda (left) '()) (task-timeout))))
      (thunk))))

;;> The step's robots as they are now, in component order, a lost member
;;> replaced; (current-team) keeps those it started with.
(define (step-team)
  (ask-team (teammate-of "step-team") "step-team" 'team (lambda (left) '())
            (task-timeout)))

(define (teammate-of who)
  (or (current-teammate)
      (error (string-append who ": not inside a team's step"))))

;;> Waits until every member of the current team has come to the barrier
;;> \var{name}, at most \var{seconds} (default: (task-timeout)); raises an
;;> error naming the members that did not come, when they run out.
(define (team-barrier name . seconds)
  (let* ((s (if (pair? seconds) (car seconds) (task-timeout)))
         (missing (ask-team (teammate-of "team-barrier") "team-barrier" 'arrive
                            (lambda (left) (list name (local-aspace-uid) left)) s)))
    (if (pair? missing)
        (error (string-append "team-barrier " (symbol->string name)
                              ": timed out waiting for")
               missing))
    #t))

;;> Sends \var{value} to the member \var{uid} of the current team.
(define (team-send! uid value)
  (let* ((m (teammate-of "team-send!"))
         (n (+ 1 (teammate-sent m))))
    (teammate-sent-set! m n)
    (ask-team m "team-send!" 'send
              (lambda (left)
                (list (list (local-aspace-uid) (teammate-nonce m) n) uid (local-aspace-uid)
                      value))
              (task-timeout))
    #t))

;;> The next value a member sent to this one, as (FROM . VALUE), waiting at
;;> most \var{seconds} (default: (task-timeout)); raises an error when none
;;> comes in time.
(define (team-receive . seconds)
  (let* ((s (if (pair? seconds) (car seconds) (task-timeout)))
         (m (teammate-of "team-receive"))
         (deadline (+ (monotonic-seconds) s)))
    (let loop ()
      (let ((letter (ask-team m "team-receive" 'receive
                              (lambda (left) (list (local-aspace-uid) (teammate-taken m) left))
                              (max 0 (seconds-until deadline)))))
        (cond ((not letter) (error "team-receive: nothing came within" s))
              (else
               (teammate-taken-set! m (letter-key letter))
               (cond ((member (letter-key letter) (teammate-seen m)) (loop))
                     (else
                      (teammate-seen-set! m (cons (letter-key letter) (teammate-seen m)))
                      (cons (letter-from letter) (letter-value letter))))))))))

;; What m's team coordinator answers to OP, applied to what args-of
;; makes of the seconds left; a kept one is found again wherever the lab
;; holds it, until seconds run out.
(define (ask-team m who op args-of seconds)
  (let ((deadline (+ (monotonic-seconds) seconds)))
    (let loop ()
      (let* ((uid (teammate-uid m))
             (left (max 0 (seconds-until deadline)))
             (answer (guard (e ((and (remote-error? e) (not (remote-raised-error? e))) #f))
                       (parameterize ((remote-timeout (call-seconds m op left)))
                         (remote-apply (uid->aspace uid) team-answer (teammate-id m) op
                                       (args-of left))))))
        (cond ((pair? answer) (car answer))
              ((or (not (teammate-kept? m)) (<= (seconds-until deadline) 0))
               (error (string-append who ": the coordinator of the team "
                                     (symbol->string (teammate-id m)) " is lost"
                                     (if (teammate-kept? m)
                                         ", and no address space of the lab holds it"
                                         ""))))
              (else
               (let ((holder (team-holder (teammate-id m))))
                 (if (or (not holder) (eq? holder uid))
                     (thread-sleep! (min (team-period) (max 0 (seconds-until deadline)))))
                 (if holder (teammate-uid-set! m holder))
                 (loop))))))))

;; How long m's call of op waits for its answer: only arrive and receive
;; wait there.  A kept team's call made again counts once, so it is made
;; again after two periods, in case the coordinator it reached is cut off.
(define (call-seconds m op left)
  (let ((waits (if (memq op '(arrive receive)) left 0)))
    (if (teammate-kept? m)
        (+ waits (max 1 (* 2 (team-period))))
        (if (> waits 0) (+ waits 1) (remote-timeout)))))

(define (team-period) (setting 'heartbeat))

;; The uid of the address space that holds team id now, or #f.
(define (team-holder id)
  (let ((answers (guard (e (#t '()))
                   (parameterize ((remote-timeout (max 1 (* 2 (team-period)))))
                     (request 'lab-tasks (sendable-lambda () (team-held? id)))))))
    (cond ((find cadr answers) => car)
          (else #f))))

;; A letter as it travels and is kept: (KEY TO FROM VALUE).
(define (letter-key l) (car l))
(define (letter-to l) (cadr l))
(define (letter-from l) (list-ref l 2))
(define (letter-value l) (list-ref l 3))

;; A coordinator's address as it travels to its members: (ID UID KEPT?),
;; the team's id, the uid holding it, and whether it outlives that uid.
(define (address-id a) (car a))
(define (address-uid a) (cadr a))
(define (address-kept? a) (car (cddr a)))

;; A team's coordinator held here: its address, whether it is acted for,
;; and the procedure its members' calls apply.
(define-record-type held-team
  (make-held-team address live? proc)
  held-team?
  (address held-team-address)
  (live? held-team-live?)
  (proc held-team-proc))

;; The node's teams part: the teams held here, found by id from members'
;; calls.
(define-record-type held-teams
  (make-held-teams list lock)
  held-teams?
  (list held-teams-list held-teams-list-set!)
  (lock held-teams-lock))

(define-syntax the-teams (syntax-rules () ((_) (node-teams *node*))))

(define (open-teams!) (node-teams-set! (this-node) (make-held-teams '() (make-mutex 'teams))))

(define (find-held-team id)
  (with-lock (held-teams-lock (the-teams))
    (lambda ()
      (find (lambda (c) (eq? (address-id (held-team-address c)) id))
            (held-teams-list (the-teams))))))

;;> Whether this address space holds team \var{id} and acts for it.
(define (team-held? id)
  (let ((c (find-held-team id)))
    (and c ((held-team-live? c)) #t)))

;;> What a member's call runs where its team is: (RESULT) of applying the
;;> coordinator of team \var{id} to \var{op} and \var{args}, or #f when
;;> this address space does not hold it, or acts for it no more.
(define (team-answer id op args)
  (let ((c (find-held-team id)))
    (and c (team-held? id)
         (let ((result (apply (held-team-proc c) op args)))
           (and ((held-team-live? c)) (list result))))))

;;> Makes the coordinator of the team \var{id} here, and answers its
;;> address for with-coordinator.  \var{team-of} answers its robots once
;;> they are chosen; \var{live?} whether this address space still acts for
;;> it.  \var{keep}, unless #f, is how the team outlives this address
;;> space: (KEEP) answers the state kept for it, or #f; (KEEP STATE) keeps
;;> STATE.  Release it with release-coordinator! when the team is done.
(define (make-coordinator id team-of live? keep)
  (let ((c (make-held-team (list id (local-aspace-uid) (and keep #t)) live?
                           (coordinator-proc team-of live? keep
                                             (or (and keep (keep)) '(() ()))))))
    (with-lock (held-teams-lock (the-teams))
      (lambda ()
        (held-teams-list-set!
         (the-teams)
         (cons c (remove (lambda (x) (eq? (address-id (held-team-address x)) id))
                         (held-teams-list (the-teams)))))))
    (held-team-address c)))

;;> Forgets the coordinator at \var{address}, made here by make-coordinator.
(define (release-coordinator! address)
  (with-lock (held-teams-lock (the-teams))
    (lambda ()
      (held-teams-list-set! (the-teams)
                            (remove (lambda (c) (eq? (held-team-address c) address))
                                    (held-teams-list (the-teams)))))))

;; The coordinator's calls, its state (ARRIVED LETTERS) to begin with:
;; ARRIVED the (NAME . UID) come to a barrier, LETTERS those not known
;; taken, in the order they came.
(define (coordinator-proc team-of live? keep state)
  (let ((arrived (car state)) (letters (cadr state))
        (lock (make-mutex 'team)) (changed (make-condition-variable 'team))
        (keeping (make-mutex 'team-keeping)))
    ;; Wakes every period at least, to leave a team it acts for no more.
    (define (wait-until done? seconds)
      (let ((deadline (+ (monotonic-seconds) seconds)))
        (let loop ()
          (lock! lock)
          (cond ((done?) => (lambda (x) (unlock! lock) x))
                ((and (< (monotonic-seconds) deadline) (live?)
                      (or (unlock-waiting! lock changed (min (team-period)
                                                             (seconds-until deadline)))
                          #t))
                 (loop))
                (else (unlock! lock) #f)))))
    ;; Keeps the state as it is now, a state kept before never after a later.
    (define (change! thunk)
      (with-lock lock thunk)
      (condition-variable-broadcast! changed)
      (if keep
          (with-lock keeping
            (lambda () (keep (with-lock lock (lambda () (list arrived letters))))))))
    (define (missing name)
      (remove (lambda (u) (member (cons name u) arrived)) (team-of)))
    (define (arrive name uid seconds)
      (change! (lambda ()
                 (if (not (member (cons name uid) arrived))
                     (set! arrived (cons (cons name uid) arrived)))))
      ;; A team taken over may not have its robots yet.
      (if (wait-until (lambda () (and (pair? (team-of)) (null? (missing name)))) seconds)
          '()
          (with-lock lock (lambda () (missing name)))))
    (define (send key to from value)
      (change! (lambda ()
                 (if (not (find (lambda (l) (equal? (letter-key l) key)) letters))
                     (set! letters (append letters (list (list key to from value))))))))
    (define (receive uid taken seconds)
      (if taken
          (with-lock lock
            (lambda ()
              (set! letters (remove (lambda (l) (equal? (letter-key l) taken)) letters)))))
      (wait-until (lambda () (find (lambda (l) (eq? (letter-to l) uid)) letters))
                  seconds))
    (lambda (op . args)
      (case op
        ((team) (team-of))
        ((arrive) (apply arrive args))
        ((send) (apply send args) #t)
        ((receive) (apply receive args))
        (else (error "a coordinator does not know" op))))))

;;; What the thesis's task procedures call

;;> The procedure that answers #t, as the thesis's tasks use it.
(define (t) #t)

;;> Sorts \var{ls} by \var{less?} (the thesis's sort-list).
(define (sort-list ls less?) (list-sort less? ls))

;;> A thunk answering random integers from 0 below \var{n}.
(define (make-maxrandom n) (lambda () (random-integer n)))
