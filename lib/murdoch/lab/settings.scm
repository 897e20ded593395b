;;;; The settings table, part of (murdoch lab): every setting a lab file
;;;; may give, its default and its reader, and how read-lab reads them.

;; Every setting a lab file may give, in one table: name, default, reader.
;; Most take one value; code and delivery the rest of their clause.
;; read-lab reads each once; a running address space asks setting (node.scm).

(define-record-type setting-row
  (make-setting name default reader)
  setting?
  (name setting-name)
  (default setting-default)
  (reader setting-reader))

;; What a clause's value may be: read answers the value for what the file
;; wrote, or #f, and what says what will do.
(define-record-type reader
  (make-reader read what)
  reader?
  (read reader-read)
  (what reader-what))

(define (number-over zero what)
  (make-reader (lambda (x) (and (real? x) (> x zero) x)) what))

(define (whole-from low high what)
  (make-reader (lambda (x) (and (exact-integer? x) (<= low x high) x)) what))

(define (text what) (make-reader (lambda (x) (and (string? x) x)) what))

(define seconds (number-over 0 "a positive number of seconds"))
(define rate
  (make-reader (lambda (x) (and (real? x) (>= x 0) x)) "a number, 0 or more, per second"))
(define positive-count (whole-from 1 1000000000 "a positive whole number"))

;; A size: bytes, or a string of a number and K, M or G.
(define (size-bytes size)
  (cond ((and (exact-integer? size) (positive? size)) size)
        ((and (string? size) (> (string-length size) 1))
         (let* ((n (string-length size))
                (unit (assv (string-ref size (- n 1))
                            '((#\K . 1024) (#\M . 1048576) (#\G . 1073741824))))
                (number (string->number (substring size 0 (- n 1)))))
           (and unit number (positive? number) (exact (round (* number (cdr unit)))))))
        (else #f)))

(define (delivery-clause args)
  (cond ((equal? args '(broadcast)) args)
        ((and (pair? args) (eq? (car args) 'multicast) (pair? (cdr args))
              (string? (cadr args))
              (or (null? (cddr args))
                  (and (exact-integer? (car (cddr args))) (null? (cdr (cddr args))))))
         args)
        (else #f)))

(define setting-entries
  `((port-base 7100 ,(whole-from 1 65535 "a port number"))
    ;; sim/lab.c keeps an interface, and a robot's name, in 64 bytes.
    (interface "127.0.0.1"
               ,(make-reader
                 (lambda (x) (and (string? x) (< (string-length x) 64) x))
                 "an IPv4 address, in quotes"))
    (key-file "murdoch.key" ,(text "a file name, in quotes"))
    (max-frame 1048576 ,positive-count)
    ;; Chibi's writer cuts what nests deeper than 10,000 (code/sendable.scm).
    (max-depth 4000 ,(whole-from 1 9000 "a whole number from 1 to 9000"))
    (timeout 5 ,seconds)
    ;; At a REPL a person waits, and Ctrl-C gives a call up (cli/command.scm).
    (repl-timeout 600 ,seconds)
    (frame-timeout 5 ,seconds)
    (lease 30 ,seconds)
    (monitor-period 60 ,seconds)
    ;; How often a started task's components and poser hear from each other.
    (heartbeat 0.5 ,seconds)
    ;; A component stops when its poser is silent for orphan-periods; the
    ;; poser takes its robot for lost after lost-periods, at least 1.25
    ;; more (check-periods), so the two never run it at once (docs/tasks.md).
    (orphan-periods 2 ,(number-over 0 "a positive number of heartbeat periods"))
    (lost-periods 4 ,(number-over 0 "a positive number of heartbeat periods"))
    (max-attempts 3 ,positive-count)
    ;; How long a detached task's results stay readable after it ends.
    (keep-results 3600 ,seconds)
    ;; A task that finds too few robots free waits or fails; its priority
    ;; rises by aging a second; a poser keeps max-waiting (docs/tasks.md).
    (when-robots-busy fail
                      ,(make-reader (lambda (x) (and (memq x '(fail wait)) x))
                                    "fail or wait"))
    (aging 0.1 ,rate)
    (max-waiting 100 ,positive-count)
    ;; How many of a poser's tasks that are over (tasks) keeps.
    (tasks-kept 20 ,(whole-from 0 1000000 "a whole number, 0 or more"))
    (max-connections 256 ,positive-count)
    (max-connections-per-host 64 ,positive-count)
    (heap-max "512M" ,(make-reader size-bytes
                                   "bytes, or a size in quotes such as \"512M\""))
    ;; Chibi grows its heap by twice one allocation (code/sandbox.scm).
    (max-alloc "32M" ,(make-reader size-bytes
                                   "bytes, or a size in quotes such as \"32M\""))
    ;; Defaults of the layers' parameters, set as an address space starts
    ;; (cli/command.scm), and of the thesis's thresholds (pubsub/monitor.scm).
    (task-timeout 600 ,seconds)
    (trip-timeout 5 ,seconds)
    (trip-motion-timeout 120 ,seconds)
    (pose-task-retries 5 ,(whole-from 0 1000 "a whole number from 0 to 1000"))
    (pose-task-backoff 0.1 ,seconds)
    (battery-charging 130 ,(number-over 0 "a voltage in tenths, above 0"))
    (battery-low 100 ,(number-over 0 "a voltage in tenths, above 0"))
    (load-threshold ".75"
                    ,(make-reader (lambda (x) (and (string? x) (string->number x) x))
                                  "a load in quotes, such as \".75\""))
    (code () ,(make-reader (lambda (x) (and (every string? x) x))
                           "file names, in quotes"))
    (delivery (broadcast)
              ,(make-reader delivery-clause
                            "broadcast, or multicast \"GROUP\" [PORT]"))))

(define settings-table
  (map (lambda (entry) (apply make-setting entry)) setting-entries))

;; The clauses the simulator reads (docs/trip-protocol.md), and aspace.
(define other-clauses '(world simulator b14 aspace))

(define multi-valued '(code delivery))

;;> The value of setting \var{key} of the lab: what its file says, or the
;;> default (docs/lab-file.md).
(define (lab-setting lab key)
  (cond ((assq key (lab-settings lab)) => cdr)
        (else (error "lab-setting: no such setting" key))))

;;> The default of setting \var{key}, as the table gives it.
(define (lab-default key)
  (let ((s (or (setting-named key) (error "lab-default: no such setting" key))))
    ((reader-read (setting-reader s)) (setting-default s))))

;; The settings of the clauses, every one of the table's, checked: an
;; error names the file, the clause and what is wrong.
(define (read-settings path clauses)
  (for-each (lambda (c) (check-clause path c)) clauses)
  (check-periods path clauses
                 (map (lambda (s)
                        (let ((c (clause (setting-name s) clauses)))
                          (cons (setting-name s)
                                (if c
                                    (setting-value path c s)
                                    ((reader-read (setting-reader s))
                                     (setting-default s))))))
                      settings-table)))

;; The settings, once lost-periods leaves a stale component a period to
;; stop in: it looks every quarter period (docs/tasks.md: no ghosts).
(define (check-periods path clauses settings)
  (if (< (cdr (assq 'lost-periods settings))
         (+ (cdr (assq 'orphan-periods settings)) 1.25))
      (lab-file-error path (or (clause 'lost-periods clauses) (clause 'orphan-periods clauses))
                      "lost-periods must be at least orphan-periods + 1.25, so a component stops a period before its robot is taken for lost"))
  settings)

(define (check-clause path c)
  (if (not (and (pair? c) (symbol? (car c)) (list? c)))
      (lab-file-error path c "a clause is (NAME VALUE ...)"))
  (if (not (or (setting-named (car c)) (memq (car c) other-clauses)))
      (lab-file-error path c (string-append "no such setting"
                                            (did-you-mean (car c)
                                                          (append (map setting-name
                                                                       settings-table)
                                                                  other-clauses)))))
  (check-inside path c))

(define (setting-named name)
  (find (lambda (s) (eq? (setting-name s) name)) settings-table))

(define (setting-value path c s)
  (let* ((read (reader-read (setting-reader s)))
         (value (cond ((memq (setting-name s) multi-valued) (read (cdr c)))
                      ((and (pair? (cdr c)) (null? (cddr c))) (read (cadr c)))
                      (else #f))))
    (or value
        (lab-file-error path c (string-append (symbol->string (car c)) " takes "
                                              (reader-what (setting-reader s)))))))

(define (did-you-mean name names)
  (let ((near (find-nearest-edits (symbol->string name) (map symbol->string names))))
    (if (and (pair? near) (<= (edit-distance (symbol->string name) (car near)) 3))
        (string-append "; did you mean " (car near) "?")
        "")))
