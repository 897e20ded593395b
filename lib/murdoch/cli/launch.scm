;;;; bin/murdoch lab, pose and demo.
;;
;; Supervising processes is left to sh scripts beside bin/murdoch
;; (murdoch-lab, murdoch-demo): this side reads the lab file, which only
;; Scheme can, and hands them what they need on their command line.  The
;; lab's address spaces are forked by its loader, which has Murdoch
;; loaded already; the script says when.

;;> One line per address space of \var{lab} but those named in the list
;;> \var{except}: name, where it listens, robot
;;> or workstation, and the capabilities its lab clause gives it, as
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
;;
;; A robot whose clause has (ros2 ...) has a trip server of its own,
;; robot/ros2/trip_ros2.py, which the lab starts beside its address space
;; unless (trip-host ...) says it runs on another host.  With
;; MURDOCH_ROS2=1 (make demo ROS2=1) every simulated robot is reached so
;; too: the simulator's trip servers move to the port plan's face-trip
;; (port-base + 150 + i), where
;; robot/ros2/b14_face.py gives them a ROS 2 face under their names, and
;; each gets a trip server of its own at its usual port.

(define (ros2-everywhere?)
  (equal? (get-environment-variable "MURDOCH_ROS2") "1"))

;; The robot's (ros2 ...) clause, or the one the simulator's face gives a
;; simulated robot under MURDOCH_ROS2=1, or #f.
(define (robot-ros2 a)
  (let ((robot (lab-aspace-clause a 'robot)))
    (cond ((not robot) #f)
          ((assq 'ros2 (filter pair? (cdr robot))) => cdr)
          ((ros2-everywhere?)
           `((namespace ,(string-append "/" (symbol->string (lab-aspace-uid a))))
             ,@face-arrival))
          (else #f))))

;; A simulated B14 ends its own motions within half a millimetre and a
;; twentieth of a degree (sim/world.c); through its face it is asked to end
;; them nearly as near, so that it senses from where a direct run would.
(define face-arrival '((arrive-mm 1) (arrive-deg 0.1)))

(define (simulated? a)
  (and (lab-aspace-clause a 'robot)
       (not (assq 'ros2 (filter pair? (cdr (lab-aspace-clause a 'robot)))))))

;; One line per trip server the lab starts for a ROS 2 robot, "ros2 NAME
;; PORT-BASE ARG ...", the arguments trip_ros2.py takes; and "face
;; PORT-BASE NAME=HOST:PORT ..." for the simulator's face.
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

;;> `murdoch lab LAB`: becomes bin/murdoch-lab, found in \var{bin}, for the
;;> lab at \var{lab-file} but for the address spaces named in \var{except},
;;> which someone will start by hand (a REPL that joins as one of them,
;;> say).  \var{logs}, \var{trace} and \var{speed} are strings or #f.
;;> First it forks the lab's loader (see serve-loader), which starts each
;;> address space as \scheme{(start-aspace uid)} in a fork of its own.
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

;; "sim" when the lab has simulated robots, with the simulator's port base
;; when their trip servers move for their ROS 2 face; else "".
(define (sim-word lab)
  (cond ((not (any simulated? (lab-aspaces lab))) "")
        ((ros2-everywhere?)
         ;; The simulator puts robot i at its port base + the plan's trip + i.
         (string-append "sim --port-base "
                        (number->string (- (lab-planned-port lab 'face-trip)
                                           (planned-port 0 'trip)))))
        (else "sim")))

;; Closes a fileno through a port, which marks it closed: the collector
;; closes the descriptor of a fileno left open, whatever it is by then.
(define (close-fileno fileno open-port)
  (close-port (open-port fileno)))

(define (close-on-exec! fd) (set-file-descriptor-flags! fd 1))   ; FD_CLOEXEC

;; Makes the descriptors fds into the numbers to, for the program about
;; to be executed: by way of numbers nothing holds, so that one of fds
;; already at a number of to is not overwritten before it is copied.
(define (renumber-for-exec! fds to)
  (let ((spare (map (lambda (n) (+ n 90)) to)))
    (for-each duplicate-file-descriptor-to fds spare)
    (for-each close-on-exec! spare)
    (for-each duplicate-file-descriptor-to spare to)))

;;; The lab's loader
;;
;; Loading Murdoch costs a process most of a second of CPU (docs/speed.md),
;; and a lab of hundreds of address spaces paid it once each.  The loader
;; is forked from `murdoch lab` with Murdoch loaded and nothing else
;; started: no thread, no socket, no poller.  Each address space is a fork
;; of it, which shares its loaded pages until it writes them.  It reads
;; requests from bin/murdoch-lab, one a line, and answers each:
;;   start UID       forks address space UID, its output going to the file
;;                   the next line names; answers the child's pid;
;;   reap            answers "PID STATUS" for each child that has ended, its
;;                   status as the shell's $? has it, then "end".
;; bin/murdoch-lab, the lab's supervisor, decides what to start and when;
;; the end of its requests ends the loader.
(define (serve-loader in out start-aspace)
  (set-process-name! "murdoch-loader")
  ;; Ctrl-C is for bin/murdoch-lab, which stops the lab; the children
  ;; inherit this, as those of sh's `&` do.
  (set-signal-action! signal/interrupt #f)
  (set-signal-action! signal/quit #f)
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

;; "PID STATUS" for each child that has ended, until none has.
(define (reap-children)
  (let ((ended (waitpid -1 wait/no-hang)))
    (if (positive? (car ended))
        (cons (string-append (number->string (car ended)) " "
                             (number->string (shell-status (cadr ended))))
              (reap-children))
        '())))

;; A wait status as $? has it: the exit code, or 128 + the signal that
;; ended the process.
(define (shell-status status)
  (let ((signal (bitwise-and status #x7f)))
    (if (zero? signal)
        (bitwise-and (arithmetic-shift status -8) #xff)
        (+ 128 signal))))

;; Forks address space uid; the child leaves the loader's requests to it,
;; writes to log and reads nothing, as sh's `>>LOG 2>&1 &` would have it.
;; It dies with the loader: bin/murdoch-lab signals only the loader's
;; children, so one the loader's death left behind would be out of its
;; reach, and a lab killed outright, whose loader then ends, leaves none
;; behind.  A loader that died before the child asked is seen in its
;; parent.
(define (fork-aspace uid log in out start-aspace)
  (let* ((loader (current-process-id))
         (pid (fork)))
    (cond
     ((zero? pid)
      (set-parent-death-signal! signal/kill)
      (if (not (= (parent-process-id) loader)) (exit 1))
      (close-port in)
      (close-port out)
      (redirect! 0 "/dev/null" open/read)
      (redirect! 1 log (bitwise-ior open/write open/append open/create))
      (duplicate-file-descriptor-to 1 2)
      ;; Chibi seeds its random source when it is loaded: every fork of
      ;; the loader would draw the same numbers.
      (random-source-pseudo-randomize! default-random-source (current-process-id)
                                       (exact (floor (current-second))))
      (start-aspace uid)
      (exit 0))
     ((negative? pid) (error "the lab's loader cannot fork" uid))
     (else pid))))

;; Makes descriptor fd the file at path, opened with flags.
(define (redirect! fd path flags)
  (let ((fileno (open path flags)))
    (if (not fileno) (error "cannot open" path))
    (duplicate-file-descriptor-to fileno fd)
    (close-fileno fileno open-input-file-descriptor)))

;;> `murdoch check LAB`: reads the lab file at \var{lab-file} as every
;;> peer does, and loads its code files into an environment of received
;;> code, as an address space does: a mistake in either is an error that
;;> names the file and the line.  Starts nothing.
(define (run-check lab-file)
  (let ((lab (read-lab lab-file)))
    (check-lab-code lab (make-lab-environment lab)))
  (write-string (string-append lab-file ": no mistakes found\n")))

;;> `murdoch demo LAB`: becomes bin/murdoch-demo, found in \var{bin}.
(define (run-demo bin lab-file)
  (execute "/bin/sh" (list "/bin/sh" (string-append bin "/murdoch-demo")
                           lab-file)))

;;> `murdoch pose LAB FILE`: joins the lab as a guest, evaluates the forms
;;> of \var{task-file} in a REPL's environment (a form that raises is
;;> named by the file and its line, with the REPL's hints), poses the
;;> task its last form names (see task-of), and writes the result.
;;> pose-task's progress lines go to the standard output as it works.
;;> Exits 0 when the task completed, else 1: not-enough-takers, or a
;;> component that failed.  With \var{detach} true, the task is handed to
;;> the lab (start-task's detach): its id is written, and it exits 0 at
;;> once.
(define (run-pose lab-file task-file detach)
  (let* ((lab (read-lab lab-file))
         (env (make-repl-environment lab (join-guest lab-file "pose"))))
    (tell-who-is-away lab)
    (eval `(pose-task-progress (current-output-port)) env)
    ;; A task file answers pose-task's arguments, which are started as
    ;; start-task starts them, or a task already started (start-task,
    ;; start-steps), or the id of one handed to the lab: each is waited
    ;; for, but with detach, where pose-task's arguments are handed to
    ;; the lab and their id written.
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

;; Waits for task record t as murdoch pose does: Ctrl-C or SIGTERM cancel
;; it; writes its results and a last line with its word, and exits 0
;; when it is done.
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

;; Joins the lab at lab-file as a guest named after what and this
;; process; answers the environment received code runs in.
(define (join-guest lab-file what)
  (join-lab lab-file
            (string->symbol (string-append what "-" (number->string (current-process-id))))
            (lab-guest-port (read-lab lab-file))))

;; Writes a task's result, and exits 0 when it completed, else 1.
(define (write-result-and-exit who result status)
  (write result)
  (newline)
  (cond ((task-failed? result status)
         (write-string (string-append who ": the task did not complete\n")
                       (current-error-port))
         (exit 1))
        (else (exit 0))))

;;> `murdoch tasks LAB`: a line for each task handed to the lab: its id,
;;> state, coordinator, standby and poser.
(define (run-tasks lab-file)
  (join-guest lab-file "tasks")
  (let ((tasks (lab-tasks)))
    (if (null? tasks) (write-string "no task is handed to the lab\n"))
    (for-each (lambda (e) (write-string (string-append (lab-task-line e) "\n"))) tasks)
    (exit 0)))

;;> `murdoch wait LAB ID`: waits for the task \var{id} handed to the lab,
;;> from any peer, and writes its results as `murdoch pose` does; exits 0
;;> when it completed, else 1, and 1 with the reason when the lab does
;;> not hold it.
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

;; Whether a task that a peer waited for by its id did not complete: by
;; its status (see task-status), where every component, of every step,
;; must be done.
(define (task-failed? result status)
  (or (symbol? result) (any failed-status? status)))

(define (failed-status? s)
  (if (step-status? s)
      (any failed-status? (step-status-entries s))
      (not (eq? (car (status-state s)) 'done))))

;; On Ctrl-C (SIGINT) or SIGTERM, t is cancelled, as Ctrl-C at a REPL
;; gives its components up: each robot stops where it is and frees its
;; subjects.  A second signal ends the pose at once.  Answers a thunk
;; that answers the signal's number once one came, else #f.
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

;; What task-wait answers for t; once a signal cancelled it, at most
;; ten seconds more: a component that neither moves its robot nor calls
;; a peer stops only at its end.
(define (wait-for-task t signalled)
  (let loop ((cancelled-at #f))
    (cond ((guard (e (#t #f)) (list (task-wait t 0.5))) => car)
          ((and cancelled-at (> (- (current-second) cancelled-at) 10)) 'cancelled)
          (else (loop (or cancelled-at (and (signalled) (current-second))))))))

(define (signal-name n)
  (cond ((= n signal/interrupt) "Ctrl-C")
        ((= n signal/term) "SIGTERM")
        (else (string-append "signal " (number->string n)))))

;;> `murdoch status LAB`: joins the lab as a guest and shows what each of
;;> its address spaces says of itself (see show-status); one that does not
;;> answer within two seconds is shown away.  Exits 1 when none answers.
(define (run-status lab-file)
  (join-guest lab-file "status")
  (cond ((zero? (parameterize ((remote-timeout 2)) (write-lab-status)))
           (write-string (string-append "murdoch status: no address space of the lab"
                                        " answers (is the lab running, with the same"
                                        " MURDOCH_PORT_BASE?)\n")
                         (current-error-port))
           (exit 1))
          (else (exit 0))))

;;> The task \var{file} evaluates to in \var{env}: the value of its last
;;> form, or, when that form defines a procedure of no arguments, what the
;;> procedure answers, as the thesis's \scheme{(define (dual-sonar-task) ...)}.
(define (task-of file env)
  (let* ((entries (car (read-source file)))     ; ((FORM . LINE) ...)
         (last-value (fold (lambda (entry acc) (eval-at file entry env)) #f entries))
         (last-entry (and (pair? entries) (last entries)))
         (last-form (and last-entry (car last-entry))))
    (if (and (pair? last-form) (eq? (car last-form) 'define)
             (pair? (cadr last-form)) (null? (cdr (cadr last-form))))
        (eval-at file (cons (cadr last-form) (cdr last-entry)) env)
        last-value)))

;; The value of entry's form in env, evaluated as the REPL does, with its
;; hints (a name mistyped, the nearest one); an error names the file and
;; the line of the form, as a lab's code file's does.
(define (eval-at file entry env)
  (at-form-line file entry (lambda () (eval-with-hints (car entry) env))))

