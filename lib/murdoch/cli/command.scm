;;;; bin/murdoch: start address spaces, join a lab at a REPL.

;;> Makes this process address space \var{uid} of the lab at
;;> \var{lab-file}, serving; answers the received-code environment.
(define (join-lab lab-file uid . port)
  (start-node! (read-lab lab-file) 'aspace uid port))

;; The one start of an address space: the node of lab, each layer taking
;; its part in turn (docs/architecture.md).  SIGPIPE is ignored, as by the
;; simulator: a peer may die at any moment, and its end is seen by the
;; connection's reader, not this process's death.
(define (start-node! lab role uid port)
  (set-signal-action! signal/pipe #f)
  (open-node! lab role)
  (open-subscriber! robot-freed!)
  (open-tasks!)
  (take-tunables!)
  (let ((env (make-lab-environment))
        (entry (lab-aspace-by-uid lab uid)))
    (if entry (take-body! lab entry))
    (apply start-aspace! uid env port)
    (initialize-subscriptions! entry)
    (offer-on-joining!)
    env))

;; The settings that are the layers' parameters, set before anything runs.
(define tunables
  `((task-timeout . ,task-timeout) (trip-timeout . ,trip-timeout)
    (trip-motion-timeout . ,trip-motion-timeout)
    (pose-task-retries . ,pose-task-retries) (pose-task-backoff . ,pose-task-backoff)))

(define (take-tunables!)
  (for-each (lambda (t) ((cdr t) (setting (car t)))) tunables))

;; A robot drives its robot through trip; a workstation answers safe-reckon
;; from its position.  The simulator is up first, so one try is enough.
(define (take-body! lab entry)
  (cond
   ((lab-aspace-clause entry 'robot)
    (let ((host (lab-trip-host lab entry))
          (port (lab-trip-port lab entry)))
      (set-current-robot!
       (guard (e (#t (error (string-append "cannot reach the robot's trip server"
                                           " (is the simulator running?)")
                            (lab-aspace-uid entry) host port
                            (error-message e))))
         (trip-connect host port)))
      (im)))
   ((lab-aspace-clause entry 'position)
    => (lambda (clause) (workstation-position (cdr clause))))))

;;> `murdoch aspace LAB NAME`: be address space NAME until killed.
(define (run-aspace lab-file uid)
  (stamp-log-lines!)
  (set-process-name! (string-append "murdoch-" (symbol->string uid)))
  (join-lab lab-file uid)
  ;; After the join, not at the fork: the kernel will not collapse pages
  ;; still shared with the loader (sys/heap-watch.c).
  (heap-on-huge-pages!)
  (start-heap-guard!
   (setting 'heap-max)
   (string-append "murdoch " (symbol->string uid) ": ERROR: the heap passed"
                  " the lab's heap-max; exiting, for the lab to start it again"))
  (log-note "listening on " (aspace-host (local-aspace)) ":"
            (aspace-port (local-aspace)))
  (let wait () (thread-sleep! 3600) (wait)))

;;> Warns of the lab's address spaces that do not answer (a guest too early?).
(define (tell-who-is-away lab)
  (let* ((others (remove (lambda (uid) (eq? uid (local-aspace-uid)))
                         (map lab-aspace-uid (lab-aspaces lab))))
         (away (filter-map (lambda (o) (and (not (outcome-ok? o)) (outcome-uid o)))
                           (parameterize ((remote-timeout 2))
                             (remote-apply-all (map uid->aspace others)
                                               local-aspace-uid)))))
    (if (pair? away)
        (log-warn (if (= (length away) (length others)) "no" "not every")
                  " address space of the lab answers; away: " away
                  " (is the lab running, with the same MURDOCH_PORT_BASE?)"))))

;;> `murdoch repl LAB [NAME]`: join the lab and read-eval-print.
(define (run-repl lab-file uid)
  (let* ((lab (read-lab lab-file))
         (guest? (not uid))
         (uid (or uid (string->symbol
                       (string-append "guest-" (number->string
                                                (current-process-id))))))
         (lab-env (start-node! lab 'repl uid
                                 (if guest? (list (lab-guest-port lab)) '()))))
    (write-string (string-append "murdoch: a REPL in the lab "
                                 (symbol->string (lab-name lab)) ", as "
                                 (symbol->string uid) "; (help) says what to type,"
                                 " Ctrl-D leaves\n"))
    (tell-who-is-away lab)
    ;; (chibi repl) is loaded, not imported: it costs seconds.
    ((eval 'repl (environment '(chibi repl)))
          'in: (waiting-input-port)
          'environment: (with-help (make-repl-environment lab lab-env))
          'eval: eval-with-hints
          'raw?: (not (is-a-tty? (current-input-port)))
          ;; write, not write/ss, so a value met twice reads as itself.
          'printer: (lambda (value out) (write value out))
          'make-prompt: (lambda (module)
                          (string-append (symbol->string uid) "> ")))
    (exit 0)))

;; env, where (help) writes help-text.
(define (with-help env)
  (eval `(define (help) (write-string ,help-text) (if #f #f)) env)
  env)

(define help-text
  "You are a peer of the lab, as any address space.  A few things to type:
  (show-status)                      each address space: pose, battery, what it holds
  (known-uids)                       the address spaces this one knows
  (remote-apply (uid->aspace 'troy) (lambda () (+ 1 2)))
                                     run a procedure on troy, and answer its value
  (request '(sonar mobile) safe-reckon)
                                     ask every robot with sonar where it is
  (pose-task 'NAME N CAPABILITIES METRICS PROCEDURES)
                                     pose a task: the best robots run its components
  (define t (start-task ...))        the same, answering at once: then (task-status t),
                                     (task-wait t), (cancel-task t)
docs/tutorial.md walks through these; docs/reference.md has every procedure.
")

;; Standard input, read so that the REPL's wait for a line lets the other
;; threads run: its own file description made non-blocking, not the shell's.
(define (waiting-input-port)
  (let ((fd (guard (e (#t #f))
              (open "/proc/self/fd/0" (bitwise-ior open/read open/non-block)))))
    (if fd
        (open-input-file-descriptor fd #t)
        (current-input-port))))
