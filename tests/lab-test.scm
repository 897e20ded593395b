;;; bin/murdoch lab and pose, as real processes: a lab comes up and goes
;;; down whole, an address space that dies is started again, one that
;;; cannot start stops the lab, and pose poses the task a file names.
;;; tests/run: long
(import (scheme base) (scheme write) (scheme file) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system system? kill signal/kill signal/interrupt
              signal/term)
        (chibi io) (chibi net)
        (only (chibi filesystem) open-input-file-descriptor)
        (murdoch testing harness))

;; Workstations only, so that no simulator is needed: the launcher starts
;; one only for labs with robots.
(define lab
  (make-test-lab '((heap-max "160M")
                   (aspace troy (capabilities camera)) (aspace praline))))
(define dir (test-lab-directory lab))
(define base (test-lab-port-base lab))

(define (in-dir name) (string-append dir "/" name))

(define (start-lab! out)
  (start-murdoch-lab! (list (test-lab-file lab) "--logs" (in-dir "logs")) out))

(define (listening? port) (wait-for-port port 0))

;; Whether, within 10 s, none of ports listens: address spaces killed by
;; their loader's death end on their own time, one after another.
(define (all-stop-listening? . ports)
  (wait-until 10 (lambda () (not (any listening? ports)))))

;; The pid of the child of process `pid` that ps names `name`, or #f.
(define (child-named pid name)
  (let ((found (string->number
                (command-output
                 (list "sh" "-c" (string-append "ps -o pid=,comm= --ppid \"$0\" | awk"
                                                " '$2 == \"" name "\" { p = $1 }"
                                                " END { print p + 0 }'")
                       (number->string pid))))))
    (and (positive? found) found)))

;; The lab's loader: the child of the lab's process `pid` that forks its
;; address spaces.
(define (loader-of pid) (child-named pid "murdoch-loader"))

;; Whether the kernel gives a process 2 MB pages when it asks (madvise).
(define (huge-pages-on?)
  (not (equal? "0" (command-output
                    (list "sh" "-c" "grep -c '\\[always\\]\\|\\[madvise\\]' /sys/kernel/mm/transparent_hugepage/enabled")))))

;; The kilobytes of process pid's memory on 2 MB pages.
(define (huge-page-kb pid)
  (string->number
   (command-output
    (list "sh" "-c" "awk '/^AnonHugePages:/ { print $2 }' /proc/$0/smaps_rollup"
          (number->string pid)))))

;; The parent of process `pid`, as /proc has it.
(define (parent-of pid)
  (string->number (command-output (list "ps" "-o" "ppid=" "-p" (number->string pid)))))

;; Whether process pid has ended: it is gone, or a zombie its new parent
;; has yet to reap.
(define (ended? pid)
  (let ((stat (guard (e (#t #f))
                (file-text (string-append "/proc/" (number->string pid) "/stat")))))
    (or (not stat)
        (text-contains? stat ") Z "))))

;; The lines `bin/murdoch COMMAND LAB ARG ...` prints.
(define (command-lines command . args)
  (let ((out (in-dir "command.out")))
    (apply system? "sh" "-c"
           "out=$1; shift; timeout -s KILL 60 \"$@\" >\"$out\" 2>&1"
           "command" out (tool-path "bin/murdoch") command (test-lab-file lab) args)
    (read-lines out)))

;; The exit status of `bin/murdoch COMMAND LAB ARG ...`.
(define (command-status command . args)
  (let ((status (apply system "sh" "-c" "timeout -s KILL 60 \"$@\" >/dev/null 2>&1"
                       "command" (tool-path "bin/murdoch") command (test-lab-file lab)
                       args)))
    (quotient (if (pair? status) (cadr status) status) 256)))

;; The lines `bin/murdoch pose` prints for the task file `task`.
(define (pose-output task) (command-lines "pose" (in-dir task)))

;; The result `bin/murdoch pose` prints for the task file `task`: the
;; line before its last, which says how the task ended.
(define (pose-result task) (before-last (pose-output task)))

(define (before-last lines)
  (if (> (length lines) 1) (list-ref lines (- (length lines) 2)) ""))

(define (address port)
  (string-append "127.0.0.1:" (number->string port)))

(test-begin "lab")

(test-group "a lab starts whole and stops whole"
  (let ((pid (start-lab! (in-dir "lab.out"))))
    (test "one line per address space, then ready"
        (list (string-append "lab: troy " (address base) " workstation camera")
              (string-append "lab: praline " (address (+ base 1)) " workstation")
              "lab: ready")
      (cdr (read-lines (in-dir "lab.out"))))
    (test "every address space listens" '(#t #t)
      (map listening? (list base (+ base 1))))
    (test "its log lines say when, and who" #t
      (let ((line (car (read-lines (in-dir "logs/troy.log")))))
        (and (char=? (string-ref line 4) #\-) (char=? (string-ref line 10) #\T)
             (text-contains? line "Z murdoch troy: listening on"))))
    (test "its address spaces are forks of one loader, a child of the lab" #t
      (let ((loader (loader-of pid)))
        (and loader
             (equal? (list loader loader)
                     (map (lambda (uid) (parent-of (child-named loader uid)))
                          '("murdoch-troy" "murdoch-praline"))))))
    ;; The fork's first writes split the loader's 2 MB pages into 4 KB
    ;; ones, unless the address space moves its heap (heap-on-huge-pages!).
    (test "a forked address space's heap is on 2 MB pages, where the kernel has them"
        (huge-pages-on?)
      (< 2048 (huge-page-kb (child-named (loader-of pid) "murdoch-troy"))))
    (test "ps names each address space murdoch-UID" '(#t #t)
      (map (lambda (uid)
             (not (equal? "0" (command-output
                               (list "sh" "-c"
                                     (string-append "ps -eo comm | grep -c '^murdoch-"
                                                    uid "$'"))))))
           '("troy" "praline")))
    (test-group "pose"
      (call-with-output-file (in-dir "task.scm")
        (lambda (out)
          (write-string "(list 'where 1 (list (list '() (list 'camera)))
                               (list load-metric)
                               (list (lambda () (local-aspace-uid))))\n"
                        out)))
      (call-with-output-file (in-dir "thunk.scm")
        (lambda (out)
          (write-string "(define (where-task)
                           (list 'where 1 (list (list '() (list 'camera)))
                                 (list load-metric)
                                 (list (lambda () 'called))))\n"
                        out)))
      (test (string-append "the task a file's last form evaluates to is posed;"
                           " the result ends the output")
          "(troy)" (pose-result "task.scm"))
      (test "pose-task's progress comes first" #t
        (text-contains? (car (pose-output "task.scm")) "pose-task: where"))
      (test "a file that defines its task as a procedure: it is called"
          "(called)" (pose-result "thunk.scm"))
      (call-with-output-file (in-dir "started.scm")
        (lambda (out)
          (write-string "(start-task 'where 1 (list (list '() (list 'camera)))
                                    (list load-metric)
                                    (list (lambda () 'started)))\n"
                        out)))
      (test "a file whose task is already started: it is waited for"
          "(started)" (pose-result "started.scm"))
      ;; Guests took port-base + 150 + (pid mod 50), and clashed; here
      ;; other processes hold every one of those ports.
      (let ((squatters (map (lambda (i)
                              (make-listener-socket
                               (get-address-info "127.0.0.1" (+ base 150 i)) 5))
                            (iota 50))))
        (test "ten guests joining at once each listen where the kernel says, and pose"
            (make-list 10 "(troy)")
          (begin
            (system? "sh" "-c"
                     "i=0; while [ $i -lt 10 ]; do i=$((i+1));
                        timeout -s KILL 120 \"$1\" pose \"$2\" \"$3\" >\"$4.$i\" 2>&1 &
                      done; wait"
                     "guests" (tool-path "bin/murdoch") (test-lab-file lab)
                     (in-dir "task.scm") (in-dir "guest.out"))
            (map (lambda (i)
                   (let ((lines (read-lines (in-dir (string-append "guest.out."
                                                                   (number->string i))))))
                     (before-last lines)))
                 (iota 10 1))))
        (for-each (lambda (sock) (close-port (open-input-file-descriptor sock)))
                  squatters))
      (test "a task done: pose exits 0" 0 (command-status "pose" (in-dir "task.scm")))
      (call-with-output-file (in-dir "draw.scm")
        (lambda (out)
          (write-string "(list 'draw 2 (list (list '() (list 'troy))
                                             (list '() (list 'praline)))
                               (list #f #f)
                               (list (lambda () ((make-maxrandom 1000000000)))
                                     (lambda () ((make-maxrandom 1000000000)))))\n"
                        out)))
      (test "forks of one loader draw random numbers of their own" #t
        (let ((draws (read (open-input-string (pose-result "draw.scm")))))
          (and (= (length draws) 2) (not (= (car draws) (cadr draws))))))
      (call-with-output-file (in-dir "failing.scm")
        (lambda (out)
          (write-string "(list 'fails 1 (list (list '() (list 'camera))) (list #f)
                               (list (lambda () (car '()))))\n"
                        out)))
      (test "a task whose component failed: pose exits 1" 1
        (command-status "pose" (in-dir "failing.scm")))
      (test "pose's last lines say how it ended, as its progress did" #t
        (let ((lines (pose-output "failing.scm")))
          (and (any (lambda (l) (and (text-contains? l "component 1 failed on troy: ")
                                     (text-contains? l "car")))
                    lines)
               (text-contains? (last lines) "murdoch pose: fails@pose-")
               (text-contains? (last lines) " failed: "))))
      (test "and a task done says done" #t
        (let ((line (last (pose-output "task.scm"))))
          (and (text-contains? line "murdoch pose: where@pose-")
               (text-contains? line " done"))))
      (call-with-output-file (in-dir "spin.scm")
        (lambda (out)
          (write-string "(list 'spin 1 (list (list (list 'camera) '())) (list #f)
                               (list (lambda ()
                                       (let loop ()
                                         (remote-apply (uid->aspace 'praline)
                                                       (lambda () 1))
                                         (thread-sleep! 0.05)
                                         (loop)))))\n"
                        out)))
      (for-each
       (lambda (signal name code)
         (let* ((out (in-dir (string-append "spin-" name ".out")))
                (pose (start-process! (list (tool-path "bin/murdoch") "pose"
                                            (test-lab-file lab) (in-dir "spin.scm"))
                                      out))
                (spinning? (lambda ()
                             (any (lambda (l) (text-contains? l "runs component 1 of spin@"))
                                  (command-lines "status")))))
           (test (string-append name " on pose: the component ran first") #t
             (wait-until 30 spinning?))
           (kill pose signal)
           (test (string-append name " on pose: it exits " (number->string code)) code
             (quotient (reap! pose) 256))
           (test (string-append name " on pose: one line says the components are given up")
               #t
             (let ((line (last (read-lines out))))
               (and (text-contains? line " cancelled by ")
                    (text-contains? line "robots stop where they are"))))
           (test (string-append name " on pose: troy stops it and frees its subjects") #t
             (wait-until 10 (lambda ()
                              (not (any (lambda (l) (or (text-contains? l "spin@")
                                                        (text-contains? l "camera held")))
                                        (command-lines "status"))))))))
       (list signal/interrupt signal/term) '("Ctrl-C" "SIGTERM") '(130 143))
      (call-with-output-file (in-dir "typo.scm")
        (lambda (out)
          (write-string ";; load-metric, mistyped\n(list 'where 1 (list (list '() (list 'camera)))
                               (list load-metrc) (list (lambda () 1)))\n"
                        out)))
      (test "a name mistyped in a task file: its file, its form's line, the nearest name"
          #t
        (any (lambda (line)
               (text-contains? line (string-append (in-dir "typo.scm") ":2: load-metrc"
                                                   " is not defined; did you mean"
                                                   " load-metric?")))
             (pose-output "typo.scm")))
      (test "and pose exits non-zero" #f
        (zero? (command-status "pose" (in-dir "typo.scm")))))
    (test "status: each address space, up" '(#t #t)
      (let ((lines (command-lines "status")))
        (map (lambda (uid)
               (any (lambda (l) (text-contains? l (string-append uid "  up "))) lines))
             '("troy" "praline"))))
    (let ((status (stop-process! pid)))
      (if (not (zero? status)) (display (file-text (in-dir "lab.out"))))
      (test "SIGTERM: the lab exits 0" 0 status))
    (test "and nothing listens any more" '(#f #f)
      (map listening? (list base (+ base 1))))
    (let ((output (pose-output "task.scm")))
      (test "pose with the lab gone says that nobody answers" #t
        (text-contains? (car output)
                        "no address space of the lab answers; away: (troy praline)"))
      (test "and nobody takes the task" "not-enough-takers" (before-last output))
      (test "its last line says it failed" #t
        (text-contains? (last output) " failed: not-enough-takers")))
    (test "a task nobody took: pose exits 1" 1
      (command-status "pose" (in-dir "task.scm")))
    (test "status, when no address space answers, exits 1" 1
      (command-status "status"))))

(test-group "an address space that dies is started again"
  (let* ((pid (start-lab! (in-dir "lab2.out")))
         (loader (loader-of pid))
         (troy (child-named loader "murdoch-troy")))
    (kill troy signal/kill)
    (test "the lab names it, and how it died" #t
      (wait-until 10 (lambda () (text-contains? (file-text (in-dir "lab2.out"))
                                                "troy died (killed by signal 9)"))))
    (test "and not with its old log lines" #f
      (text-contains? (file-text (in-dir "lab2.out")) "listening on"))
    (test "and starts it again" #t
      (wait-until 30 (lambda () (and (text-contains? (file-text (in-dir "lab2.out"))
                                                     "starting troy again")
                                     (listening? base)))))
    (test "the others carry on" #t (listening? (+ base 1)))
    (test "forked again by the same loader" #t
      (let ((again (child-named loader "murdoch-troy")))
        (and again (not (= again troy)))))
    ;; Three restarts a minute: the fourth death is the last.
    (let loop ((deaths 1) (killed troy))
      (when (< deaths 4)
        (let ((next #f))
          (wait-until 30 (lambda ()
                           (set! next (child-named loader "murdoch-troy"))
                           (and next (not (= next killed)) (listening? base))))
          (kill next signal/kill)
          (loop (+ deaths 1) next))))
    (test "the fourth death in a minute is counted as four" #t
      (wait-until 30 (lambda () (text-contains? (file-text (in-dir "lab2.out"))
                                                "troy died 4 times in a minute"))))
    (test "the lab runs on, and stops whole" 0 (stop-process! pid))))

(test-group "a fork past heap-max ends, and is forked again"
  ;; Logs of its own: the group before used up troy's restarts this minute.
  (let ((pid (start-murdoch-lab! (list (test-lab-file lab) "--logs" (in-dir "logs6"))
                                 (in-dir "lab6.out"))))
    (call-with-output-file (in-dir "hog.scm")
      (lambda (out)
        (write-string "(list 'hog 1 (list (list '() (list 'troy))) (list #f)
                             (list (lambda ()
                                     (let loop ((kept '()))
                                       (loop (cons (make-vector 1000 0) kept))))))\n"
                      out)))
    (test "its component fails: pose exits 1" 1
      (command-status "pose" (in-dir "hog.scm")))
    (test "the lab names it, with the heap guard's line" #t
      (wait-until 10 (lambda ()
                       (let ((text (file-text (in-dir "lab6.out"))))
                         (and (text-contains? text "troy died (exit code 3)")
                              (text-contains? text
                                              "the heap passed the lab's heap-max"))))))
    (test "and starts it again" #t
      (wait-until 30 (lambda () (and (text-contains? (file-text (in-dir "lab6.out"))
                                                     "starting troy again")
                                     (listening? base)))))
    (test "the lab stops whole" 0 (stop-process! pid))))

(test-group "the loader's death stops the lab"
  (let* ((pid (start-lab! (in-dir "lab5.out"))))
    (kill (loader-of pid) signal/kill)
    (test "the lab exits non-zero" #t (not (zero? (reap! pid))))
    (test "saying so" #t
      (text-contains? (file-text (in-dir "lab5.out")) "the loader"))
    (test "and stops the address spaces" #t (all-stop-listening? base (+ base 1)))))

(test-group "a lab killed outright leaves nothing behind"
  ;; No SIGTERM for the lab to stop them by: its loader reads the end of
  ;; its requests and ends, and the address spaces end with it; the view
  ;; ends with the lab's process.
  (let* ((pid (start-murdoch-lab! (list "--logs" (in-dir "logs7") "--view"
                                        (test-lab-file lab))
                                  (in-dir "lab7.out")))
         (troy (child-named (loader-of pid) "murdoch-troy"))
         (view (child-named pid "murdoch-view")))
    (kill pid signal/kill)
    (reap! pid)
    (test "its address spaces end" #t (wait-until 10 (lambda () (ended? troy))))
    (test "and they stop listening" #t (all-stop-listening? base (+ base 1)))
    (test "and so does its view" #t (and view (wait-until 10 (lambda () (ended? view)))))))

(test-group "a child that cannot start stops the lab, with its ERROR line"
  ;; troy's port is taken before the lab starts.
  (let* ((squatter (make-listener-socket (get-address-info "127.0.0.1" base) 5))
         (out (in-dir "lab4.out"))
         (pid (start-process! (list (tool-path "bin/murdoch") "lab" (test-lab-file lab)
                                    "--logs" (in-dir "logs4"))
                              out)))
    (test "the lab exits non-zero" #t (not (zero? (reap! pid))))
    (test "naming the child and what went wrong" '(#t #t)
      (let ((text (file-text out)))
        (list (text-contains? text "troy died")
              (text-contains? text "is another process there?"))))
    (test "and stops the others" #f (listening? (+ base 1)))
    (close-port (open-input-file-descriptor squatter))))

(test-group "a REPL waiting for a line still serves the lab"
  ;; praline is a REPL whose input never comes: a peer all the same.
  (let ((pid (start-murdoch-lab! (list (test-lab-file lab) "--except" "praline")
                                 (in-dir "lab3.out")))
        ;; Its input is a FIFO it holds open itself, for writing too.
        (repl (start-process!
               (list "/bin/sh" "-c"
                     (string-append "mkfifo \"$2\" && exec 3<>\"$2\""
                                    " && exec \"$0\" repl \"$1\" praline <&3 3<&-")
                     (tool-path "bin/murdoch") (test-lab-file lab) (in-dir "fifo"))
               (in-dir "repl.out"))))
    (call-with-output-file (in-dir "asks-praline.scm")
      (lambda (out)
        (write-string "(list 'who 1 (list (list '() (list 'praline))) (list #f)
                              (list (lambda () (local-aspace-uid))))\n"
                      out)))
    (test "the REPL waits for a line" #t
      (wait-until 60 (lambda () (text-contains? (file-text (in-dir "repl.out"))
                                                "praline> "))))
    (test "and takes a task posed from elsewhere" "(praline)"
      (pose-result "asks-praline.scm"))
    (call-with-output-file (in-dir "fifo")
      (lambda (out)
        (write-string (string-append "(remote-apply (uid->aspace 'troy)"
                                     " (lambda () (thread-sleep! 6) 'slept))\n")
                      out)))
    (test "a call from the REPL outlasts the lab's 5 s timeout (repl-timeout)" #t
      (wait-until 30 (lambda ()
                       (text-contains? (file-text (in-dir "repl.out")) "slept"))))
    (stop-process! repl)
    (stop-process! pid)))

(test "a lab removed after a failed test shows its logs' last lines first"
    "the last line"
  (command-output
   (list "/bin/sh" "-c"
         (string-append "tools/chibi tests/failing-lab.scm 2>&1"
                        " | grep -A2 '^--- the last lines of a.log' | tail -1"))))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
