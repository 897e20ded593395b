;;;; Finding a detached task from anywhere, part of (murdoch task
;;;; detached): the lab-tasks subject, and task-status, task-wait and
;;;; cancel-task by id at the member that holds the task.

;;> This address space's entry for each detached task it holds: (ID ROLE
;;> EPOCH STATE COORDINATOR STANDBY POSER TOOK-OVER), read by the
;;> lab-task- procedures.
(define (handed-entries)
  (map (lambda (h)
         (let ((me (local-aspace-uid)) (role (handed-role h)))
           (list (handed-id h) role (handed-epoch h) (copy-state (handed-copy h))
                 (if (eq? role 'standby) (handed-partner h) me)
                 (if (eq? role 'standby) me (handed-partner h))
                 (handed-poser h) (handed-took-over h))))
       (with-lock (handing-lock (the-handing)) (lambda () (handing-list (the-handing))))))

;;> The task's id in \var{e}, an entry of lab-tasks or handed-entries.
(define (lab-task-id e) (car e))
;;> The role of the address space that gave \var{e}, an entry of
;;> lab-tasks: coordinator, standby or let-go.
(define (lab-task-role e) (cadr e))
;;> How many coordinators the task of \var{e} has had.
(define (lab-task-epoch e) (list-ref e 2))
;;> The state of the task of \var{e}, an entry of lab-tasks.
(define (lab-task-state e) (list-ref e 3))
;;> The coordinator's uid in \var{e}, an entry of lab-tasks.
(define (lab-task-coordinator e) (list-ref e 4))
;;> The standby's uid in \var{e}, or #f while there is none.
(define (lab-task-standby e) (list-ref e 5))
;;> The uid that posed the task of \var{e}.
(define (lab-task-poser e) (list-ref e 6))
;;> When the coordinator of \var{e} took the task over, or #f.
(define (lab-task-took-over e) (list-ref e 7))

;;> The lab's detached tasks, one entry each, as its coordinator (or, in
;;> a takeover, its standby) says: see handed-entries.
(define (lab-tasks)
  (let ((all (append-map cadr (guard (e (#t '()))
                                (request 'lab-tasks handed-entries)))))
    (filter-map (lambda (id) (best-entry (filter (lambda (e) (eq? (lab-task-id e) id)) all)))
                (delete-duplicates (map lab-task-id all)))))

;; Of the entries for one task, the coordinator's of the latest epoch, else
;; the standby's.
(define (best-entry entries)
  (let ((ranked (list-sort (lambda (a b)
                             (or (> (lab-task-epoch a) (lab-task-epoch b))
                                 (and (= (lab-task-epoch a) (lab-task-epoch b))
                                      (eq? (lab-task-role a) 'coordinator))))
                           (remove (lambda (e) (eq? (lab-task-role e) 'let-go)) entries))))
    (and (pair? ranked) (car ranked))))

;; The uid that answers for task id now; moving while the only member
;; that holds it has let it go, its standby silent (it takes the task
;; back, or the standby takes it over, within take-over-periods); or #f.
(define (holder-of id)
  (let* ((entries (append-map cadr
                              (guard (e (#t '()))
                                (parameterize ((remote-timeout (max 1 (* 2 (period)))))
                                  (request 'lab-tasks
                                           (sendable-lambda ()
                                             (filter (lambda (e) (eq? (lab-task-id e) id))
                                                     (handed-entries))))))))
         (e (best-entry entries)))
    (cond (e (if (eq? (lab-task-role e) 'standby)
                 (lab-task-standby e)
                 (lab-task-coordinator e)))
          ((pair? entries) 'moving)
          (else #f))))

;; Applies proc to id's record where it is held, waiting while it moves;
;; raises a clear error when nobody holds it.
(define (at-holder who id moving proc . args)
  (let ((moving-until (+ (monotonic-seconds) moving)))
    (let try ((left 2))
      (let ((uid (holder-of id)))
        (cond
         ((and (eq? uid 'moving) (< (monotonic-seconds) moving-until))
          (thread-sleep! (period))
          (try left))
         ((and (memq uid '(#f moving)) (> left 0)) (thread-sleep! (period)) (try (- left 1)))
         ((eq? uid 'moving) (error (string-append who ": " (moving-text id))))
         ((not uid) (error (string-append who ": " (not-held-text id))))
         (else
          (guard (e ((and (remote-error? e) (not (remote-raised-error? e)) (> left 0))
                     (thread-sleep! (period))
                     (try (- left 1))))
            (apply remote-apply (uid->aspace uid) proc id args))))))))

;; How long to wait for a task that moves (take-over-periods).
(define (moving-seconds) (* (+ (take-over-periods) 4) (period)))

(define (moving-text id)
  (string-append "the task " (symbol->string id) " is moving: the member that"
                 " coordinated it let it go, its standby silent (stalled, or cut off"
                 " from it); one of them takes it, or it fails; ask again in a moment"))

(define (not-held-text id)
  (let ((seen (components-of id)))
    (string-append
     "no address space of the lab holds the task " (symbol->string id)
     (if (pair? seen)
         (string-append
          ": it failed, its coordinator and its standby both lost; its components"
          " stopped as orphans on " (uid-list-text (delete-duplicates (map car seen))))
         (string-append
          ": no such task, or it ended more than keep-results seconds ago,"
          " or its coordinator and its standby were both lost")))))

(define (uid-list-text uids)
  (let ((out (open-output-string)))
    (for-each (lambda (u i) (if (> i 0) (write-string ", " out)) (display u out))
              uids (iota (length uids)))
    (get-output-string out)))

;;> What task-status answers for the detached task \var{id}, here where
;;> it is held.
(define (handed-status id)
  (let ((h (handed-by-id id)))
    (cond ((not h) (error "no such detached task here" id))
          ((and (handed-task h) (eq? (handed-role h) 'coordinator)
                (not (copy-results (handed-copy h))))
           (task-status (handed-task h)))
          (else (copy-status (handed-copy h))))))

;;> What task-wait waits for, here where the detached task \var{id} is
;;> held: (done RESULTS), or (not-yet) after \var{seconds}.
(define (handed-wait id seconds)
  (let ((h (handed-by-id id)))
    (cond ((not h) (error "no such detached task here" id))
          ((copy-results (handed-copy h)) (list 'done (copy-results (handed-copy h))))
          ((and (handed-task h) (eq? (handed-role h) 'coordinator))
           (guard (e ((error-object? e) '(not-yet)))
             (list 'done (task-wait (handed-task h) seconds))))
          (else (thread-sleep! (min seconds (period))) '(not-yet)))))

;;> What cancel-task does, here where the detached task \var{id} is
;;> held.
(define (handed-cancel id)
  (let ((h (handed-by-id id)))
    (cond ((and h (handed-task h) (eq? (handed-role h) 'coordinator))
           (cancel-task (handed-task h)))
          (else (error "task is not coordinated here now" id)))))

;;; By id or by record

;;> The state of each component of \var{task}, a task record or a
;;> detached task's id: see task-status in (murdoch task life-cycle).
(define (task-status task)
  (if (symbol? task)
      (at-holder "task-status" task (moving-seconds) handed-status)
      (status-here task)))

;;> Waits for \var{task}, a record or a detached task's id, as task-wait
;;> in (murdoch task life-cycle); a detached task is waited for where it
;;> is coordinated, and found again after a takeover.
(define (task-wait task . seconds)
  (if (symbol? task)
      (let ((until (and (pair? seconds) (+ (monotonic-seconds) (car seconds)))))
        (let loop ()
          (let* ((left (if until (- until (monotonic-seconds)) 10))
                 ;; A task that moves is waited for as one that runs.
                 (answer (parameterize ((remote-timeout (+ (min left 10) 5)))
                           (at-holder "task-wait" task (if until (max 0 left) 3600)
                                      handed-wait (max 0 (min left 10))))))
            (cond ((eq? (car answer) 'done) (cadr answer))
                  ((and until (<= (- until (monotonic-seconds)) 0))
                   (error (string-append "task-wait: " (symbol->string task)
                                         " is not done within "
                                         (number->string (car seconds)) " s")))
                  (else (loop))))))
      (apply wait-here task seconds)))

;;> Cancels \var{task}, a record or a detached task's id, as cancel-task
;;> in (murdoch task life-cycle).
(define (cancel-task task)
  (if (symbol? task)
      (at-holder "cancel-task" task (moving-seconds) handed-cancel)
      (cancel-here task)))

