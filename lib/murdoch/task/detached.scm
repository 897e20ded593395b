;;;; Tasks handed to the lab: a detached task's coordinator and its standby.
;;
;; start-task and start-steps with 'detach #t hand the task to the lab,
;; which keeps it on two of its members (docs/tasks.md, "Tasks handed to
;; the lab", gives the argument):
;;
;;  1. The poser hands the task to the least loaded coordinator other
;;     than itself, answers its id, and may leave.
;;  2. The coordinator does for it all a poser does, and copies its record
;;     to a standby, chosen the same way, on every change and every
;;     period, and a step's team before a member's call is answered.
;;  3. Never two coordinators: the coordinator acts only while its
;;     standby's pings arrive; the standby takes over after four periods
;;     unanswered, or one after it finds the coordinator's process gone.
;;  4. Taking over, it adopts each component where it runs, negotiates
;;     again a task not started, and chooses a new standby.
;;  5. Any peer finds the task by id through the lab-tasks subject.
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

;; The node's handing part: the tasks handed here, coordinated or stood
;; by for, which the calls of peers find by id.
(define-record-type handing
  (make-handing list lock)
  handing?
  (list handing-list handing-list-set!)
  (lock handing-lock))

(define-syntax the-handing (syntax-rules () ((_) (node-handing *node*))))

(define (open-handing!)
  (node-handing-set! (this-node) (make-handing '() (make-mutex 'handed))))

(define (handed-by-id id)
  (with-lock (handing-lock (the-handing))
    (lambda () (find (lambda (h) (eq? (handed-id h) id)) (handing-list (the-handing))))))

(define (hold-handed! h)
  (let ((hs (the-handing)))
    (with-lock (handing-lock hs)
      (lambda ()
        (handing-list-set! hs (cons h (remove (lambda (x) (eq? (handed-id x) (handed-id h)))
                                              (handing-list hs))))
        (subscribe 'lab-tasks)))))

(define (drop-handed! h)
  (let ((hs (the-handing)))
    (with-lock (handing-lock hs)
      (lambda ()
        (handing-list-set! hs (remove (lambda (x) (eq? x h)) (handing-list hs)))
        (if (null? (handing-list hs)) (unsubscribe 'lab-tasks))))))

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
