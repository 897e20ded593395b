;;;; The live view's table of tasks, part of (murdoch view): who holds
;;;; what, for which task, from what the address spaces report.

;;; The tasks: what the address spaces say they hold and run
;;
;; A robot tells the subjects it holds and for whom -- a reservation
;; name, NAME@POSER/N (pose-task.scm) -- and the components of started
;; tasks that it runs, (running ID INDEX POSER) with ID NAME@POSER/N
;; (task.scm).  The table remembers each component from when it is first
;; seen on a robot to when that robot no longer shows it; a component of
;; a started task seen on another robot than before was reassigned.  A
;; task's own state is what its poser says, when the poser is an address
;; space of the lab; else running while a component is seen, then done,
;; or failed when a component was lost.  A component is lost when its
;; robot started again (its up-since moved) or has not answered for
;; away-polls looks in a row: a robot that died does not say that it
;; stopped, and its poser was told "connection lost".

(define-record-type task-entry
  (make-task-entry key name poser state components)
  task-entry?
  (key task-entry-key)
  (name task-entry-name)
  (poser task-entry-poser)
  (state task-entry-state task-entry-state-set!)
  (components task-entry-components task-entry-components-set!))

(define-record-type component-entry
  (make-component-entry index robot subjects since until end from)
  component-entry?
  (index component-entry-index)
  (robot component-entry-robot)
  (subjects component-entry-subjects component-entry-subjects-set!)
  (since component-entry-since)
  (until component-entry-until component-entry-until-set!)
  (end component-entry-end component-entry-end-set!)
  (from component-entry-from))

;;> A table of the tasks seen so far, empty.
(define (make-task-table) (list (list 'robots)))

;; The car of a table holds, after 'robots, (ROBOT UP-SINCE AWAY) for each
;; robot seen: when it last started, and how many looks in a row it has
;; not answered.
(define (table-tasks table) (cdr table))
(define (table-robots table) (car table))

(define away-polls 3)

;;> The task name and poser that reservation name or task id \var{key}
;;> (a string, NAME@POSER/N: task-key's) holds, as a list, or the key and
;;> #f when it is not one.
(define (reservation-task key)
  (or (task-key-parts key) (list key #f)))

;; NAME@POSER of a key: what a started task's id and its reservations share.
(define (key-base key)
  (let ((nt (reservation-task key)))
    (if (cadr nt) (string-append (car nt) "@" (cadr nt)) key)))

;; What one address space's report shows running there: (KEY INDEX
;; SUBJECTS) for each component, INDEX #f when only held subjects show it.
(define (report-components report)
  (let* ((held (map (lambda (h) (cons (text (car h)) (text (cadr h))))
                    (report-held report)))
         (running (filter-map (lambda (t)
                                (and (pair? t) (eq? (car t) 'running)
                                     (>= (length t) 3)
                                     (list (text (cadr t)) (list-ref t 2))))
                              (report-tasks report)))
         (subjects-of (lambda (pred)
                        (map car (filter (lambda (h) (pred (cdr h))) held))))
         (covered? (lambda (holder)
                     (any (lambda (r) (equal? (key-base (car r)) (key-base holder)))
                          running))))
    (append
     (map (lambda (r)
            (list (car r) (cadr r)
                  (subjects-of (lambda (holder)
                                 (equal? (key-base holder) (key-base (car r)))))))
          running)
     (map (lambda (holder)
            (list holder #f (subjects-of (lambda (h) (equal? h holder)))))
          (delete-duplicates (remove covered? (map cdr held)))))))

;; (KEY STATE) for each task the report says this address space posed.
(define (report-posed report)
  (filter-map (lambda (t)
                (and (pair? t) (eq? (car t) 'posed) (memv (length t) '(3 5))
                     (list (text (cadr t))
                           (if (= (length t) 5)
                               (string-append "waiting, " (text (list-ref t 3))
                                              " in line")
                               (text (car (cddr t)))))))
              (report-tasks report)))

(define (task-named table key)
  (or (find (lambda (t) (equal? (task-entry-key t) key)) (table-tasks table))
      (let* ((nt (reservation-task key))
             (t (make-task-entry key (car nt) (cadr nt) #f '())))
        (set-cdr! table (append (table-tasks table) (list t)))
        t)))

(define (open? c) (not (component-entry-until c)))

(define (lost? c)
  (let ((end (component-entry-end c)))
    (and (string? end) (>= (string-length end) 5)
         (string=? "lost:" (substring end 0 5)))))

;;> Brings \var{table} up to the time \var{t} (seconds) with
;;> \var{reports}: (UID REPORT) for each address space that answered,
;;> REPORT as aspace-report makes it.  Components that an address space
;;> that answered no longer shows have ended.
(define (task-table-update! table t reports)
  (let ((seen '()))                     ; the component entries seen now
    (for-each
     (lambda (uid+report)
       (let ((robot (text (car uid+report)))
             (report (cadr uid+report)))
         (for-each (lambda (posed)
                     (task-entry-state-set! (task-named table (car posed))
                                            (cadr posed)))
                   (report-posed report))
         (for-each
          (lambda (obs)
            (set! seen (cons (observe! (task-named table (car obs)) t robot
                                       (cadr obs) (car (cddr obs)))
                             seen)))
          (report-components report))))
     reports)
    (let* ((answered (map (lambda (r) (text (car r))) reports))
           (gone (note-robots! table t reports)))
      (for-each
       (lambda (task)
         (for-each (lambda (c)
                     (cond ((and (open? c) (< (component-entry-since c) t)
                                 (assoc (component-entry-robot c) gone))
                            => (lambda (why)
                                 (component-entry-until-set! c t)
                                 (component-entry-end-set! c (cdr why))))
                           ((and (open? c) (not (memq c seen))
                                 (member (component-entry-robot c) answered))
                            (component-entry-until-set! c t)
                            (component-entry-end-set! c "done"))))
                   (task-entry-components task)))
       (table-tasks table)))))

;; Brings the table's robots up to date with reports, and answers
;; ((ROBOT . WHY) ...) for those whose components seen before were lost:
;; started again, or silent for away-polls looks.
(define (note-robots! table t reports)
  (let ((robots (table-robots table))
        (gone '()))
    (for-each
     (lambda (uid+report)
       (let* ((robot (text (car uid+report)))
              (since (cadr (cadr uid+report)))
              (entry (assoc robot (cdr robots))))
         (cond ((not entry) (set-cdr! robots (cons (list robot since 0) (cdr robots))))
               (else
                (if (not (equal? (cadr entry) since))
                    (set! gone (cons (cons robot (string-append "lost: " robot
                                                                " started again"))
                                     gone)))
                (set-car! (cdr entry) since)
                (set-car! (cddr entry) 0)))))
     reports)
    (for-each (lambda (entry)
                (when (not (any (lambda (r) (equal? (text (car r)) (car entry))) reports))
                  (set-car! (cddr entry) (+ 1 (car (cddr entry))))
                  (if (= (car (cddr entry)) away-polls)
                      (set! gone (cons (cons (car entry)
                                             (string-append "lost: " (car entry)
                                                            " does not answer"))
                                       gone)))))
              (cdr robots))
    gone))

;; The component entry of task that robot shows at t, made if new.
(define (observe! task t robot index subjects)
  (let* ((cs (task-entry-components task))
         (same (find (lambda (c)
                       (and (open? c)
                            (if index
                                (eqv? (component-entry-index c) index)
                                (and (not (component-entry-index c))
                                     (equal? (component-entry-robot c) robot)))))
                     cs)))
    (cond
     ((and same (equal? (component-entry-robot same) robot))
      (component-entry-subjects-set!
       same (lset-union equal? (component-entry-subjects same) subjects))
      same)
     (else
      (when same                        ; its index moved to another robot
        (component-entry-until-set! same t)
        (component-entry-end-set! same (string-append "moved to " robot)))
      (let* ((before (and index
                          (find (lambda (c)
                                  (and (eqv? (component-entry-index c) index)
                                       (not (equal? (component-entry-robot c) robot))))
                                (reverse cs))))
             (c (make-component-entry index robot subjects t #f #f
                                      (and before (component-entry-robot before)))))
        (task-entry-components-set! task (append cs (list c)))
        c)))))

;;> The table as JSON: the newest \var{most} tasks, each with its name,
;;> poser, state and components (index, robot, subjects, since, until,
;;> how it ended, and the robot it was reassigned from).
(define (task-table->json table most)
  (list->vector
   (map (lambda (task)
          (let ((cs (task-entry-components task)))
            `((id . ,(task-entry-key task))
              (name . ,(task-entry-name task))
              (poser . ,(or (task-entry-poser task) 'null))
              (state . ,(or (task-entry-state task)
                            (cond ((any open? cs) "running")
                                  ((any lost? cs) "failed")
                                  (else "done"))))
              (components
               . ,(list->vector
                   (map (lambda (c)
                          `((index . ,(or (component-entry-index c) 'null))
                            (robot . ,(component-entry-robot c))
                            (subjects . ,(list->vector (component-entry-subjects c)))
                            (since . ,(num (component-entry-since c)))
                            (until . ,(if (open? c)
                                          'null
                                          (num (component-entry-until c))))
                            (end . ,(or (component-entry-end c) 'null))
                            (from . ,(or (component-entry-from c) 'null))))
                        cs))))))
        (let ((all (table-tasks table)))
          (reverse (if (> (length all) most) (take-right all most) all))))))
