;;;; The live view's table of tasks, part of (murdoch view): who holds what
;;;; for which task, from the robots' reports of subjects held and
;;;; components running and ended.  A component seen on another robot was
;;;; reassigned, subjects held with none are a reservation, a component is
;;;; lost when its robot restarted or missed away-polls looks, and a task's
;;;; state is its poser's word, else its components'.

(define-record-type task-entry
  (make-task-entry key name poser state components)
  task-entry?
  (key task-entry-key)
  (name task-entry-name)
  (poser task-entry-poser)
  (state task-entry-state task-entry-state-set!)
  (components task-entry-components task-entry-components-set!)
  ;; A detached task's (COORDINATOR STANDBY), as its coordinator says.
  (keepers task-entry-keepers task-entry-keepers-set!))

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

(define-record-type task-table
  (%make-task-table robots tasks)
  task-table?
  (robots table-robots table-robots-set!)       ; seen-robots
  (tasks table-tasks table-tasks-set!))         ; task-entries, oldest first

;; A robot the table has seen: when it last started, and looks missed in a row.
(define-record-type seen-robot
  (make-seen-robot name since silent)
  seen-robot?
  (name seen-robot-name)
  (since seen-robot-since seen-robot-since-set!)
  (silent seen-robot-silent seen-robot-silent-set!))

;;> A table of the tasks seen so far, empty.
(define (make-task-table) (%make-task-table '() '()))

(define away-polls 3)

;;> The task name and poser of \var{key} (NAME@POSER/N) as a list, else (key #f).
(define (reservation-task key)
  (or (task-key-parts key) (list key #f)))

;; NAME@POSER of a key: what a started task's id and its reservations share.
(define (key-base key)
  (let ((nt (reservation-task key)))
    (if (cadr nt) (string-append (car nt) "@" (cadr nt)) key)))

;; A component one report shows: KEY its task's, INDEX #f for held subjects only.
(define-record-type shown
  (make-shown key index subjects)
  shown?
  (key shown-key)
  (index shown-index)
  (subjects shown-subjects))

(define (held-texts report)
  (map (lambda (h) (cons (text (held-subject h)) (text (held-holder h))))
       (report-held report)))

;; A shown for each component one report shows running there.
(define (report-components report)
  (let* ((held (held-texts report))
         (running (filter-map (lambda (t)
                                (and (pair? t) (not (listed-posed? t))
                                     (>= (length t) 3)
                                     (make-shown (text (listed-id t)) (listed-index t)
                                                 '())))
                              (report-tasks report)))
         (subjects-of (lambda (pred)
                        (map car (filter (lambda (h) (pred (cdr h))) held))))
         (covered? (lambda (holder)
                     (any (lambda (r) (equal? (key-base (shown-key r)) (key-base holder)))
                          running))))
    (append
     (map (lambda (r)
            (make-shown (shown-key r) (shown-index r)
                        (subjects-of (lambda (holder)
                                       (equal? (key-base holder)
                                               (key-base (shown-key r)))))))
          running)
     (map (lambda (holder)
            (make-shown holder #f (subjects-of (lambda (h) (equal? h holder)))))
          (delete-duplicates (remove covered? (map cdr held)))))))

;; (KEY . STATE) for each of tasks, as (tasks) answers, posed by the answerer.
(define (posed-states tasks)
  (filter-map (lambda (t)
                (and (pair? t) (listed-posed? t) (>= (length t) 3)
                     (cons (text (listed-id t))
                           (posed-state-text t (and (= (length t) 8) (listed-place t))))))
              tasks))

;; A posed task's state as shown: its word, why it failed, or what it waits for.
(define (posed-state-text t place)
  (let ((word (text (listed-state t))))
    (cond ((< (length t) 8) word)       ; a peer older than the word's details
          ((memq (listed-state t) '(waiting holding))
           (string-append word ": " (waiting-text t place)))
          ((string? (listed-why t)) (string-append word ": " (listed-why t)))
          (else word))))

;; Whether the table takes a posed (KEY . STATE): a task over unseen is left out.
(define (posed-news? table posed)
  (or (task-known table (car posed))
      (not (any (lambda (word) (string-prefix? word (cdr posed)))
                '("done" "failed" "cancelled" "deadline")))))

;;> Brings \var{table}'s waiting tasks up to date with \var{line}, the lab's.
(define (task-table-note-line! table line)
  (let ((keys (map (lambda (x) (text (listed-id (car (cddr x))))) line)))
    (for-each (lambda (x key)
                (task-entry-state-set! (task-named table key)
                                       (posed-state-text (car (cddr x)) (cadr x))))
              line keys)
    (for-each (lambda (task)
                (let ((state (task-entry-state task)))
                  (if (and (string? state)
                           (or (string-prefix? "waiting" state)
                               (string-prefix? "holding" state))
                           (not (member (task-entry-key task) keys)))
                      (task-entry-state-set! task #f))))
              (table-tasks table))))

(define (string-prefix? prefix s)
  (and (>= (string-length s) (string-length prefix))
       (string=? prefix (substring s 0 (string-length prefix)))))

(define (ended-entries report)
  (filter (lambda (e)
            (and (list? e) (= (length e) 6) (exact-integer? (ended-index e))
                 (real? (ended-started e)) (real? (ended-ended e))
                 (pair? (ended-end e))))
          (report-ended report)))

;; (done), (failed WHY) or (lost WHY) as "done", "failed: WHY" ..., WHY cut short.
(define (end-text end)
  (if (pair? (cdr end))
      (let ((why (text (cadr end))))
        (string-append (text (car end)) ": "
                       (if (> (string-length why) 160)
                           (string-append (substring why 0 160) " ...")
                           why)))
      (text (car end))))

(define (task-known table key)
  (find (lambda (t) (equal? (task-entry-key t) key)) (table-tasks table)))

(define (task-named table key)
  (or (task-known table key)
      (let* ((nt (reservation-task key))
             (t (make-task-entry key (car nt) (cadr nt) #f '())))
        (task-entry-keepers-set! t #f)
        (table-tasks-set! table (append (table-tasks table) (list t)))
        t)))

(define (open? c) (not (component-entry-until c)))

(define (failed? c)
  (let ((end (component-entry-end c)))
    (and (string? end)
         (any (lambda (word)
                (and (>= (string-length end) (string-length word))
                     (string=? word (substring end 0 (string-length word)))))
              '("lost:" "failed:")))))

;; Whether c failed or was lost, and no later entry took its number.
(define (failed-for-good? c cs)
  (and (failed? c)
       (let ((k (component-entry-index c)))
         (not (and k (any (lambda (later) (eqv? (component-entry-index later) k))
                          (cdr (memq c cs))))))))

;; A task's state by its components, when its poser does not say.
(define (components-state cs)
  (cond ((any (lambda (c) (and (open? c) (component-entry-index c))) cs) "running")
        ((any open? cs) "negotiating")
        ((any (lambda (c) (equal? (component-entry-end c) "cancelled")) cs) "cancelled")
        ((any (lambda (c) (failed-for-good? c cs)) cs) "failed")
        ((any component-entry-index cs) "done")
        (else "not started")))

;;> Brings \var{table} up to time \var{t} with \var{reports}, (UID REPORT
;;> [POSED]) each; a component no longer shown has ended or was released.
(define (task-table-update! table t reports)
  (let ((seen '()))                     ; the component entries seen now
    (for-each
     (lambda (r)
       (let ((robot (text (sighting-uid r)))
             (report (sighting-report r)))
         (for-each (lambda (posed)
                     (if (posed-news? table posed)
                         (task-entry-state-set! (task-named table (car posed))
                                                (cdr posed))))
                   (posed-states (or (sighting-posed r) (report-tasks report))))
         (for-each
          (lambda (shown)
            (set! seen (cons (observe! table (task-named table (shown-key shown)) t
                                       robot (shown-index shown) (shown-subjects shown))
                             seen)))
          (report-components report))
         (for-each (lambda (e) (note-ended! table t robot e))
                   (ended-entries report))
         (for-each (lambda (e)
                     (when (eq? (lab-task-role e) 'coordinator)
                       (let ((task (task-named table (text (lab-task-id e)))))
                         (task-entry-keepers-set!
                          task (list (text (lab-task-coordinator e))
                                     (if (lab-task-standby e)
                                         (text (lab-task-standby e))
                                         'null)))
                         (task-entry-state-set! task (text (lab-task-state e))))))
                   (report-handed report))))
     reports)
    (let* ((answered (map (lambda (r) (text (sighting-uid r))) reports))
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
                            (component-entry-end-set!
                             c (if (component-entry-index c) "ended" "released")))))
                   (task-entry-components task)))
       (table-tasks table)))))

;; The parts of a sighting, (UID REPORT [POSED]), as the view and tests make it.
(define (sighting-uid r) (car r))
(define (sighting-report r) (cadr r))
(define (sighting-posed r) (and (pair? (cddr r)) (car (cddr r))))

;; Brings the table's robots up to date: ((ROBOT . WHY) ...) for those lost.
(define (note-robots! table t reports)
  (let ((gone '()))
    (for-each
     (lambda (r)
       (let* ((robot (text (sighting-uid r)))
              (since (report-since (sighting-report r)))
              (entry (find (lambda (s) (equal? (seen-robot-name s) robot))
                           (table-robots table))))
         (cond ((not entry)
                (table-robots-set! table (cons (make-seen-robot robot since 0)
                                               (table-robots table))))
               (else
                (if (not (equal? (seen-robot-since entry) since))
                    (set! gone (cons (cons robot (string-append "lost: " robot
                                                                " started again"))
                                     gone)))
                (seen-robot-since-set! entry since)
                (seen-robot-silent-set! entry 0)))))
     reports)
    (for-each (lambda (entry)
                (let ((robot (seen-robot-name entry)))
                  (when (not (any (lambda (r) (equal? (text (sighting-uid r)) robot))
                                  reports))
                    (seen-robot-silent-set! entry (+ 1 (seen-robot-silent entry)))
                    (if (= (seen-robot-silent entry) away-polls)
                        (set! gone (cons (cons robot (string-append "lost: " robot
                                                                    " does not answer"))
                                         gone))))))
              (table-robots table))
    gone))

;; The component entry of task that robot shows at t, made if new.
(define (observe! table task t robot index subjects)
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
             (reserved (and index (take-reservations! table task robot)))
             (c (make-component-entry index robot subjects (or reserved t) #f #f
                                      (and before (component-entry-robot before)))))
        (task-entry-components-set! task (append (task-entry-components task)
                                                 (list c)))
        c)))))

;; The unnumbered reservations robot holds for task become the component
;; starting there; answers when the first was seen, or #f.
(define (take-reservations! table task robot)
  (let ((base (key-base (task-entry-key task)))
        (since #f))
    (for-each
     (lambda (other)
       (when (equal? (key-base (task-entry-key other)) base)
         (let ((held (filter (lambda (c) (and (open? c) (not (component-entry-index c))
                                              (equal? (component-entry-robot c) robot)))
                             (task-entry-components other))))
           (for-each (lambda (c)
                       (set! since (min (or since +inf.0) (component-entry-since c))))
                     held)
           (task-entry-components-set!
            other (remove (lambda (c) (memq c held)) (task-entry-components other))))))
     (table-tasks table))
    (table-tasks-set! table
                      (remove (lambda (other) (and (null? (task-entry-components other))
                                                   (not (task-entry-state other))
                                                   (not (eq? other task))))
                              (table-tasks table)))
    since))

;; Ends robot's component that e tells of: the open entry, or a new one.
(define (note-ended! table t robot e)
  (let* ((key (text (ended-id e)))
         (k (ended-index e))
         (ended-at (- t (ended-ended e)))
         (end (end-text (ended-end e)))
         (task (if (>= ended-at 0) (task-named table key) (task-known table key)))
         (c (and task
                 (find (lambda (c) (and (eqv? (component-entry-index c) k)
                                        (equal? (component-entry-robot c) robot)))
                       (task-entry-components task)))))
    (cond ((and c (open? c)) (end-component! c ended-at end))
          ((and task (not c))
           (end-component! (observe! table task (- t (ended-started e)) robot k '())
                           ended-at end)))))

(define (end-component! c until end)
  (component-entry-until-set! c until)
  (component-entry-end-set! c end))

;; Whether a goes before b: a smaller number, or a number before none.
(define (by-number a b)
  (let ((i (component-entry-index a)) (j (component-entry-index b)))
    (and i (or (not j) (< i j)))))

;;> The table as JSON: the newest \var{most} tasks and their components.
(define (task-table->json table most)
  (list->vector
   (map (lambda (task)
          (let ((cs (task-entry-components task)))
            `((id . ,(task-entry-key task))
              (name . ,(task-entry-name task))
              (poser . ,(or (task-entry-poser task) 'null))
              (coordinator . ,(let ((k (task-entry-keepers task))) (if k (car k) 'null)))
              (standby . ,(let ((k (task-entry-keepers task))) (if k (cadr k) 'null)))
              (state . ,(or (task-entry-state task) (components-state cs)))
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
                        (list-stable-sort by-number cs)))))))
        (let ((all (table-tasks table)))
          (reverse (if (> (length all) most) (take-right all most) all))))))
