;;;; bin/murdoch lab, pose and demo: this side reads the lab file for the
;;;; sh scripts bin/murdoch-lab and bin/murdoch-demo, which supervise.

;;> One line per address space of \var{lab} not in \var{except}, as
;;> \scheme{"moseley 127.0.0.1:7100 robot (trip 127.0.0.1:7200) sonar mobile"}.
(define (lab-lines lab except)
  (map (lambda (a)
         (string-join
          (cons* (symbol->string (lab-aspace-uid a))
                 (address (lab-aspace-host a) (lab-aspace-port a))
                 (append (body-words lab a)
                         (map symbol->string (capabilities a))))))
       (remove (lambda (a) (memq (lab-aspace-uid a) except))
               (lab-aspaces lab))))

(define (body-words lab a)
  (if (lab-aspace-clause a 'robot)
      (list "robot" (string-append "(trip " (address (lab-aspace-host a)
                                                     (lab-trip-port lab a))
                                   ")"))
      (list "workstation")))

;;; Robots reached through ROS 2 (docs/ros2.md)
;; A (ros2 ...) robot has its own trip server, robot/ros2/trip_ros2.py,
;; started by the lab unless on a trip-host.  Under MURDOCH_ROS2=1 the
;; simulated robots too, behind robot/ros2/b14_face.py at face-trip.

(define (ros2-everywhere?)
  (equal? (get-environment-variable "MURDOCH_ROS2") "1"))

;; The robot's (ros2 ...) clause, or its face's under MURDOCH_ROS2=1, or #f.
(define (robot-ros2 a)
  (let ((robot (lab-aspace-clause a 'robot)))
    (cond ((not robot) #f)
          ((assq 'ros2 (filter pair? (cdr robot))) => cdr)
          ((ros2-everywhere?)
           `((namespace ,(string-append "/" (symbol->string (lab-aspace-uid a))))
             ,@face-arrival))
          (else #f))))

;; A simulated B14 stops within 0.5 mm and 0.05° (sim/world.c); through
;; its face nearly as near, to sense from where a direct run would.
(define face-arrival '((arrive-mm 1) (arrive-deg 0.1)))

(define (simulated? a)
  (and (lab-aspace-clause a 'robot)
       (not (assq 'ros2 (filter pair? (cdr (lab-aspace-clause a 'robot)))))))

;; A line per trip server the lab starts: "ros2 NAME PORT-BASE ARG ..."
;; (trip_ros2.py's), and "face PORT-BASE NAME=HOST:PORT ..." for the face.
(define (ros2-lines lab)
  (let ((base (number->string (lab-port-base lab))))
    (append
     (if (and (ros2-everywhere?) (any simulated? (lab-aspaces lab)))
         (list (string-join
                (cons* "face" base
                       (map (lambda (a)
                              (string-append (symbol->string (lab-aspace-uid a)) "="
                                             (address (lab-trip-host lab a)
                                                      (face-port lab a))))
                            (filter simulated? (lab-aspaces lab))))))
         '())
     (filter-map
      (lambda (a)
        (let ((ros2 (robot-ros2 a)))
          (and ros2 (not (robot-trip-host a))
               (string-join
                (cons* "ros2" (symbol->string (lab-aspace-uid a)) base
                       (trip-ros2-arguments lab a ros2))))))
      (lab-aspaces lab)))))

(define (robot-trip-host a)
  (assq 'trip-host (filter pair? (cdr (lab-aspace-clause a 'robot)))))

;; Where the simulator serves robot a's trip under MURDOCH_ROS2=1.
(define (face-port lab a)
  (lab-planned-port lab 'face-trip (lab-aspace-index a)))

(define (trip-ros2-arguments lab a ros2)
  (cons* "--name" (symbol->string (lab-aspace-uid a))
         "--host" (lab-aspace-host a)
         "--port" (number->string (lab-trip-port lab a))
         (append-map (lambda (c)
                       (append-map (lambda (v)
                                     (list (string-append "--" (symbol->string (car c)))
                                           (cond ((string? v) v)
                                                 ((symbol? v) (symbol->string v))
                                                 (else (number->string v)))))
                                   (cdr c)))
                     ros2)))

(define (capabilities a)
  (cond ((lab-aspace-clause a 'capabilities) => cdr) (else '())))

(define (address host port) (string-append host ":" (number->string port)))

(define (string-join words)
  (fold (lambda (w acc) (string-append acc " " w)) (car words) (cdr words)))

;;> `murdoch lab LAB`: becomes bin/murdoch-lab (in \var{bin}) for the lab,
;;> but for the address spaces in \var{except}, after forking the loader.
(define (run-lab bin lab-file except logs trace speed start-aspace)
  (let* ((lab (read-lab lab-file))
         (requests (open-pipe))         ; bin/murdoch-lab -> the loader
         (answers (open-pipe))          ; the loader -> bin/murdoch-lab
         (loader (fork)))
    (cond
     ((zero? loader)
      (close-fileno (cadr requests) open-output-file-descriptor)
      (close-fileno (car answers) open-input-file-descriptor)
      (serve-loader (open-input-file-descriptor (car requests))
                    (open-output-file-descriptor (cadr answers))
                    start-aspace))
     (else
      (for-each close-on-exec! (append requests answers))
      (renumber-for-exec! (list (cadr requests) (car answers)) '(3 4))
      (execute "/bin/sh"
               (cons* "/bin/sh" (string-append bin "/murdoch-lab") lab-file
                      (or logs "") (or trace "") (or speed "")
                      (sim-word lab)
                      (number->string loader)
                      (append (ros2-lines lab) (lab-lines lab except))))))))

;; "sim" and the simulator's port base when the lab has simulated robots.
(define (sim-word lab)
  (cond ((not (any simulated? (lab-aspaces lab))) "")
        ((ros2-everywhere?)
         ;; The simulator puts robot i at its port base + the plan's trip + i.
         (string-append "sim --port-base "
                        (number->string (- (lab-planned-port lab 'face-trip)
                                           (planned-port 0 'trip)))))
        (else "sim")))

;; Closes a fileno through a port, marking it closed for the collector.
(define (close-fileno fileno open-port)
  (close-port (open-port fileno)))

(define (close-on-exec! fd) (set-file-descriptor-flags! fd 1))   ; FD_CLOEXEC

;; Moves the descriptors fds to the numbers to for exec, by way of free ones.
(define (renumber-for-exec! fds to)
  (let ((spare (map (lambda (n) (+ n 90)) to)))
    (for-each duplicate-file-descriptor-to fds spare)
    (for-each close-on-exec! spare)
    (for-each duplicate-file-descriptor-to spare to)))

;;; The lab's loader
;; Loading Murdoch costs a process most of a second (docs/speed.md), so
;; address spaces are forks of a loader with it loaded and nothing started.
;; Its requests from bin/murdoch-lab, one a line:
;;   start UID    forks UID, logging to the next line's file; answers the pid
;;   reap         "PID STATUS" ($?'s) for each child ended, then "end"
(define (serve-loader in out start-aspace)
  (set-process-name! "murdoch-loader")
  ;; Ctrl-C is for bin/murdoch-lab; the children inherit this, as sh's `&`'s do.
  (set-signal-action! signal/interrupt #f)
  (set-signal-action! signal/quit #f)
  ;; Each fork starts with the whole free heap, not with what loading
  ;; happened to leave since its last collection (docs/speed.md).
  (gc)
  (let loop ()
    (let ((line (read-line in)))
      (cond
       ((eof-object? line) (exit 0))
       ((equal? line "reap")
        (for-each (lambda (ended) (write-line ended out)) (reap-children))
        (write-line "end" out))
       ((string-prefix? "start " line)
        (let ((uid (substring line 6 (string-length line)))
              (log (read-line in)))
          (write-line (number->string (fork-aspace uid log in out start-aspace))
                      out)))
       (else (error "the lab's loader: not a request" line)))
      (flush-output-port out)
      (loop))))

(define (write-line text out) (write-string text out) (newline out))

(define (reap-children)
  (let ((ended (waitpid -1 wait/no-hang)))
    (if (positive? (car ended))
        (cons (string-append (number->string (car ended)) " "
                             (number->string (shell-status (cadr ended))))
              (reap-children))
        '())))

;; A wait status as $? has it: the exit code, or 128 + the signal.
(define (shell-status status)
  (let ((signal (bitwise-and status #x7f)))
    (if (zero? signal)
        (bitwise-and (arithmetic-shift status -8) #xff)
        (+ 128 signal))))

;; Forks address space uid as sh's `>>LOG 2>&1 &`, dying with the loader,
;; as bin/murdoch-lab signals only the loader's children.
(define (fork-aspace uid log in out start-aspace)
  (let* ((loader (current-process-id))
         (pid (fork)))
    (cond
     ((zero? pid)
      (die-with-parent! loader signal/kill)
      (close-port in)
      (close-port out)
      (redirect! 0 "/dev/null" open/read)
      (redirect! 1 log (bitwise-ior open/write open/append open/create))
      (duplicate-file-descriptor-to 1 2)
      ;; Chibi seeds its random source when loaded: forks would draw alike.
      (random-source-pseudo-randomize! default-random-source (current-process-id)
                                       (exact (floor (current-second))))
      (start-aspace uid)
      (exit 0))
     ((negative? pid) (error "the lab's loader cannot fork" uid))
     (else pid))))

(define (redirect! fd path flags)
  (let ((fileno (open path flags)))
    (if (not fileno) (error "cannot open" path))
    (duplicate-file-descriptor-to fileno fd)
    (close-fileno fileno open-input-file-descriptor)))

;;> `murdoch check LAB`: reads the lab file and loads its code, starting nothing.
(define (run-check lab-file)
  (let ((lab (read-lab lab-file)))
    (open-node! lab)
    (check-lab-code lab (make-lab-environment)))
  (write-string (string-append lab-file ": no mistakes found\n")))

;;> `murdoch demo LAB`: becomes bin/murdoch-demo, found in \var{bin}.
(define (run-demo bin lab-file)
  (execute "/bin/sh" (list "/bin/sh" (string-append bin "/murdoch-demo")
                           lab-file)))

;;> `murdoch pose LAB FILE`: joins as a guest, poses the task
;;> \var{task-file} names (task-of) and writes its progress and result;
;;> exits 0 when it completed, else 1.  \var{detach} hands it to the lab.
(define (run-pose lab-file task-file detach)
  (let* ((lab (read-lab lab-file))
         (env (make-repl-environment lab (join-guest lab-file "pose"))))
    (tell-who-is-away lab)
    (eval `(pose-task-progress (current-output-port)) env)
    ;; Pose-task's arguments, a task started, or a handed task's id.
    (let ((task (task-of task-file env)))
      (cond
       (detach
        (if (not (list? task))
            (begin (write-string (string-append "murdoch pose: --detach poses the"
                                                " arguments of pose-task that "
                                                task-file " answers; it answers a task"
                                                " already started\n")
                                 (current-error-port))
                   (exit 1)))
        (write (apply start-task (append task '(detach #t))))
        (newline)
        (exit 0))
       ((symbol? task)
        (write-result-and-exit "murdoch pose" (task-wait task) (task-status task)))
       (else (wait-and-exit (if (task? task) task (apply start-task task))))))))

;; Waits for task t as murdoch pose does, exiting 0 when it is done.
(define (wait-and-exit t)
  (let* ((signalled (cancel-on-signals! t))
         (result (wait-for-task t signalled)))
    (write result)
    (newline)
    (write-string (string-append "murdoch pose: " (symbol->string (task-id t)) " "
                                 (task-state-text t)
                                 (if (signalled)
                                     (string-append
                                      " by " (signal-name (signalled))
                                      ": its robots stop where they are and their"
                                      " subjects are freed")
                                     "")
                                 "\n"))
    (exit (cond ((signalled) => (lambda (n) (+ 128 n)))
                ((eq? (task-state t) 'done) 0)
                (else 1)))))

;; Joins the lab as a guest named after what; answers the environment.
(define (join-guest lab-file what)
  (join-lab lab-file
            (string->symbol (string-append what "-" (number->string (current-process-id))))
            (lab-guest-port (read-lab lab-file))))

(define (write-result-and-exit who result status)
  (write result)
  (newline)
  (cond ((task-failed? result status)
         (write-string (string-append who ": the task did not complete\n")
                       (current-error-port))
         (exit 1))
        (else (exit 0))))

;;> `murdoch tasks LAB`: a line for each task handed to the lab.
(define (run-tasks lab-file)
  (join-guest lab-file "tasks")
  (let ((tasks (lab-tasks)))
    (if (null? tasks) (write-string "no task is handed to the lab\n"))
    (for-each (lambda (e) (write-string (string-append (lab-task-line e) "\n"))) tasks)
    (exit 0)))

;;> `murdoch wait LAB ID`: waits for task \var{id} handed to the lab, as `murdoch pose`.
(define (run-wait lab-file id)
  (join-guest lab-file "wait")
  (guard (e (#t (write-string (string-append "murdoch wait: " (error-message e) "\n")
                              (current-error-port))
                (exit 1)))
    (let ((result (task-wait id)))
      (write-result-and-exit "murdoch wait" result (task-status id)))))

;;> `murdoch cancel LAB ID`: cancels the task \var{id} handed to the lab.
(define (run-cancel lab-file id)
  (join-guest lab-file "cancel")
  (guard (e (#t (write-string (string-append "murdoch cancel: " (error-message e) "\n")
                              (current-error-port))
                (exit 1)))
    (cancel-task id)
    (write-string (string-append "cancelled " (symbol->string id) "\n"))
    (exit 0)))

;; Whether a task waited for by id failed: every component must be done.
(define (task-failed? result status)
  (or (symbol? result) (any failed-status? status)))

(define (failed-status? s)
  (if (step-status? s)
      (any failed-status? (step-status-entries s))
      (not (eq? (car (status-state s)) 'done))))

;; SIGINT or SIGTERM cancel t, a second one ends the pose; answers a thunk
;; of the signal, or #f.
(define (cancel-on-signals! t)
  (let ((caught #f))
    (for-each (lambda (signal)
                (set-signal-action! signal
                                    (lambda (n)
                                      (if caught (exit (+ 128 n)))
                                      (set! caught n)
                                      (cancel-task t))))
              (list signal/interrupt signal/term))
    (lambda () caught)))

;; What task-wait answers for t, at most ten seconds after a signal.
(define (wait-for-task t signalled)
  (let loop ((cancelled-at #f))
    (cond ((guard (e (#t #f)) (list (task-wait t 0.5))) => car)
          ((and cancelled-at (> (- (current-second) cancelled-at) 10)) 'cancelled)
          (else (loop (or cancelled-at (and (signalled) (current-second))))))))

(define (signal-name n)
  (cond ((= n signal/interrupt) "Ctrl-C")
        ((= n signal/term) "SIGTERM")
        (else (string-append "signal " (number->string n)))))

;;> `murdoch status LAB`: what each address space says of itself
;;> (show-status); exits 1 when none answers.
(define (run-status lab-file)
  (join-guest lab-file "status")
  (cond ((zero? (parameterize ((remote-timeout 2)) (write-lab-status)))
           (write-string (string-append "murdoch status: no address space of the lab"
                                        " answers (is the lab running, with the same"
                                        " MURDOCH_PORT_BASE?)\n")
                         (current-error-port))
           (exit 1))
          (else (exit 0))))

;;> The task \var{file} evaluates to: its last form's value, or what the
;;> procedure of no arguments it defines answers.
(define (task-of file env)
  (let* ((entries (car (read-source file)))     ; ((FORM . LINE) ...)
         (last-value (fold (lambda (entry acc) (eval-at file entry env)) #f entries))
         (last-entry (and (pair? entries) (last entries)))
         (last-form (and last-entry (car last-entry))))
    (if (and (pair? last-form) (eq? (car last-form) 'define)
             (pair? (cadr last-form)) (null? (cdr (cadr last-form))))
        (eval-at file (cons (cadr last-form) (cdr last-entry)) env)
        last-value)))

;; The value of entry's form in env, as the REPL's; errors name file and line.
(define (eval-at file entry env)
  (at-form-line file entry (lambda () (eval-with-hints (car entry) env))))

