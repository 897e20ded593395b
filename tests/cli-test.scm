;;; bin/murdoch's command line: help, version, and a mistake said in one
;;; line with the usage, exit 2, and no stack trace.
;;; tests/run: long
(import (scheme base) (scheme write) (scheme file) (srfi 1) (chibi test)
        (only (chibi process) system current-process-id)
        (only (chibi filesystem) delete-file-hierarchy open-input-file-descriptor)
        (only (chibi net) make-listener-socket get-address-info)
        (chibi json) (murdoch testing harness))

(define dir (temporary-directory))
(define out (string-append dir "/out"))

;; (exit-status first-line whole-output) of bin/murdoch with args.
(define (murdoch . args)
  (let ((status (apply system "sh" "-c"
                       (string-append "cd \"$1\" && shift"
                                      " && exec timeout -s KILL 60 bin/murdoch \"$@\""
                                      " >\"$0\" 2>&1")
                       out (tool-path ".") args)))
    (let ((text (file-text out)))
      (list (quotient (if (pair? status) (cadr status) status) 256)
            (let ((lines (text-lines text))) (if (pair? lines) (car lines) ""))
            text))))

(define (status r) (car r))
(define (first-line r) (cadr r))
(define (no-trace? r) (not (text-contains? (car (cddr r)) "called from")))

(define (write-file name text)
  (call-with-output-file (string-append dir "/" name)
    (lambda (o) (write-string text o))))

(test-begin "cli")

(test-group "help and version"
  (let ((r (murdoch "--help")))
    (test "--help: exit 0" 0 (status r))
    (test "lists every command" #t
      (every (lambda (c) (text-contains? (car (cddr r)) (string-append "murdoch " c)))
              '("aspace" "repl" "lab" "pose" "demo" "view" "replay" "check" "help"))))
  (test "help lab lists its options" '(0 #t)
    (let ((r (murdoch "help" "lab")))
      (list (status r) (text-contains? (car (cddr r)) "--logs"))))
  (test "lab --help too" '(0 #t)
    (let ((r (murdoch "lab" "--help")))
      (list (status r) (text-contains? (car (cddr r)) "--except"))))
  (test "help lab: --view, whose port may be left out" '(0 #t)
    (let ((r (murdoch "help" "lab")))
      (list (status r) (text-contains? (car (cddr r)) "--view PORT"))))
  (test "--version" '(0 "murdoch 0.3")
    (let ((r (murdoch "--version"))) (list (status r) (first-line r)))))

(test-group "mistakes: one line, the usage, exit 2"
  (define (mistake args line)
    (let ((r (apply murdoch args)))
      (test (string-append "murdoch " (if (pair? args) (car args) "")) (list 2 line #t)
        (list (status r) (first-line r) (no-trace? r)))))
  (mistake '() "murdoch: no command given")
  (mistake '("bogus") "murdoch: no command bogus")
  (mistake '("labb" "x") "murdoch: no command labb; did you mean lab?")
  (mistake '("aspace" "x.scm") "murdoch aspace: missing NAME")
  (mistake '("pose" "a" "b" "c") "murdoch pose: too many arguments: c")
  (mistake '("lab" "examples/tulane-lab.scm" "--bogus" "1")
           "murdoch lab: unknown option --bogus")
  (mistake '("lab" "--view") "murdoch lab: missing LAB")
  (mistake '("view" "examples/tulane-lab.scm" "http")
           "murdoch view: not a port number: http")
  (mistake '("check" "examples/tulane-lab.scm" "--bogus")
           "murdoch check: unknown option --bogus")
  (mistake '("lab" "--bogus" "examples/tulane-lab.scm")
           "murdoch lab: unknown option --bogus")
  (mistake '("lab" "--spede" "2" "examples/tulane-lab.scm")
           "murdoch lab: unknown option --spede; did you mean --speed?")
  (mistake '("lab" "--speed" "abc" "examples/tulane-lab.scm")
           "murdoch lab: --speed takes a positive number, not abc")
  (mistake '("lab" "--view" "abc" "examples/tulane-lab.scm")
           "murdoch lab: --view takes a port number, or nothing, not abc")
  (mistake '("lab" "examples/tulane-lab.scm" "--trace")
           "murdoch lab: --trace takes a name")
  (mistake '("lab" "--speed=abc" "examples/tulane-lab.scm")
           "murdoch lab: --speed takes a positive number, not abc")
  (test "--speed=2 takes its value with it, and leaves LAB an argument"
      "murdoch lab: ERROR: cannot read /no/such.scm: couldn't open input file"
    (first-line (murdoch "lab" "--speed=2" "/no/such.scm")))
  (mistake '("repl" "examples/tulane-lab.scm" "--x") "murdoch repl: unknown option --x")
  (test "a mistake in what a command reads is one ERROR line" '(2 #t)
    (let ((r (murdoch "check" "/no/such/lab.scm")))
      (list (status r)
            (string=? (car (cddr r))
                      (string-append "murdoch check: ERROR: cannot read /no/such/lab.scm:"
                                     " couldn't open input file\n")))))
  (test "a replay of a file that is not a trace, such as a lab file" #t
    (let ((r (murdoch "replay" "examples/tulane-lab.scm")))
      (and (= 2 (status r))
           (equal? (text-lines (car (cddr r)))
                   (list (string-append
                          "murdoch replay: ERROR: not a trace of the view:"
                          " examples/tulane-lab.scm (a trace's first line is the view's"
                          " header of the room)"))))))
  (test "a replay of a trace that is not there"
      '(2 "murdoch replay: ERROR: no such trace /no/such.jsonl")
    (let ((r (murdoch "replay" "/no/such.jsonl")))
      (list (status r) (first-line r)))))

(test-group "replay follows MURDOCH_PORT_BASE, as lab and view do"
  (let* ((base (free-port-base dir))
         (trace (string-append dir "/trace.jsonl"))
         (replay-out (string-append dir "/replay.out")))
    (write-file "trace.jsonl"
                (string-append "{\"kind\":\"lab\",\"lab\":\"x\",\"radius\":180,"
                               "\"walls\":[],\"boxes\":[],\"aspaces\":[],"
                               "\"started\":0}\n"))
    (let ((pid (start-process! (list "env" (string-append "MURDOCH_PORT_BASE="
                                                          (number->string base))
                                     (tool-path "bin/murdoch") "replay" trace)
                               replay-out)))
      (test "it serves on port-base + 148" #t
        (wait-until 30 (lambda ()
                         (text-contains? (file-text replay-out)
                                         (string-append "http://127.0.0.1:"
                                                        (number->string (+ base 148))
                                                        "/")))))
      (stop-process! pid))))

;; Every base claimed by an existing folder, each claim's asker as given.
(define (claim-every-base! claims asker)
  (system "sh" "-c"
          (string-append
           "e=$(cut -f1 /proc/sys/net/ipv4/ip_local_port_range); mkdir -p \"$0\";"
           " i=0; while [ $i -lt $(( (e - 10200) / 200 )) ]; do"
           "  b=$(( 10000 + i * 200 )); rm -rf \"$0/$b\"; mkdir \"$0/$b\";"
           "  echo \"$0\" > \"$0/$b/pid\"; echo \"$1\" > \"$0/$b/asker\"; i=$((i + 1)); done")
          claims asker))

;; free-port-base's exit status with claims as its claims folder.
(define (free-port-base-status claims)
  (let ((status (system "sh" "-c" "MURDOCH_PORT_CLAIMS=\"$0\" \"$1\" \"$0\" >/dev/null 2>&1"
                        claims (tool-path "tools/free-port-base"))))
    (quotient (if (pair? status) (cadr status) status) 256)))

(test-group "a port base held by a folder is free once its asker has ended"
  ;; A run killed before it removed its folder held its base for ever,
  ;; until no base was left for any lab on the machine.
  (let ((claims (string-append dir "/claims")))
    (claim-every-base! claims (number->string (current-process-id)))
    (test "a live asker's claims stand: no base is free" 1
      (free-port-base-status claims))
    (claim-every-base! claims "999999999")
    (test "an ended asker's claims are free again" 0
      (free-port-base-status claims))))

(test-group "before anything is built"
  ;; A copy of bin/ and tools/chibi with no Chibi beside it or on PATH,
  ;; and C not yet compiled.
  (let ((fresh (string-append dir "/fresh")))
    (system "sh" "-c" (string-append "mkdir -p \"$1/bin\" \"$1/tools\" \"$1/lib/murdoch\""
                                     " && cp bin/murdoch bin/murdoch.scm \"$1/bin\""
                                     " && cp tools/chibi \"$1/tools\""
                                     " && echo \"(include-shared \\\"glue\\\")\""
                                     " >\"$1/lib/murdoch/glue.sld\"")
            (tool-path ".") fresh)
    (let ((status (system "sh" "-c"
                          "PATH=/usr/bin:/bin \"$1/bin/murdoch\" --help >\"$0\" 2>&1"
                          out fresh)))
      (test "--help says what to run, and exits 1" '(1 #t)
        (list (quotient (if (pair? status) (cadr status) status) 256)
              (text-contains? (file-text out) "run `make all`"))))))

(test-group "check"
  (test "a good lab file" '(0 "examples/tulane-lab.scm: no mistakes found")
    (let ((r (murdoch "check" "examples/tulane-lab.scm")))
      (list (status r) (first-line r))))
  (call-with-output-file (string-append dir "/lab.scm")
    (lambda (o) (write-string "(lab x (timout 3))\n" o)))
  (test "a misspelt setting" #t
    (let ((r (murdoch "check" (string-append dir "/lab.scm"))))
      (and (= 2 (status r)) (text-contains? (first-line r) "did you mean timeout?"))))
  (write-file "inside.scm"
              "(lab x\n  (aspace a (robot (pose 0 0 0)\n    (tetherd #f))))\n")
  (test "check and lab name the same mistake inside a robot, with its line"
      (map (lambda (command)
             (list 2 (string-append "murdoch " command ": ERROR: " dir
                                    "/inside.scm:3: (tetherd #f):"
                                    " no such clause in robot; did you mean tethered?")))
           '("check" "lab"))
    (map (lambda (command)
           (let ((r (murdoch command (string-append dir "/inside.scm"))))
             (list (status r) (first-line r))))
         '("check" "lab")))
  ;; A code file is loaded as an address space loads it.
  (write-file "open.scm" "(define (f x)\n  (+ x 1)\n\n(define (g) 2)\n")
  (write-file "raises.scm" "(define a 1)\n(car '())\n")
  (write-file "code1.scm" "(lab x (code \"open.scm\"))\n")
  (write-file "code2.scm" "(lab x (code \"raises.scm\"))\n")
  (test "a code file whose list is not closed: its file and line" #t
    (let ((r (murdoch "check" (string-append dir "/code1.scm"))))
      (and (= 2 (status r))
           (text-contains?
            (first-line r)
            "/open.scm:1: this list has no closing ): the file ends inside it"))))
  (test "a code file that raises as it loads: its file, line and error" #t
    (let ((r (murdoch "check" (string-append dir "/code2.scm"))))
      (and (= 2 (status r))
           (text-contains? (first-line r) "/raises.scm:2: car: not a pair ()"))))
  ;; Loading lets a name that nothing defines pass, in a procedure's body
  ;; or a later form's: only a robot running it would say.
  (write-file "typo.scm" (string-append "(define (f) (g))\n(define (g) 'quoted-name)\n"
                                        ";; load-metric, mistyped\n"
                                        "(define (h)\n  (let loop ((i 3))\n"
                                        "    (if (> i 0) (loop (- i 1)) (lod-metric))))\n"))
  (write-file "code3.scm" "(lab x (code \"typo.scm\"))\n")
  (test "a name that a code file uses and nothing defines: its file, line, nearest name"
      #t
    (let ((r (murdoch "check" (string-append dir "/code3.scm"))))
      (and (= 2 (status r))
           (text-contains? (first-line r)
                           (string-append "/typo.scm:4: lod-metric is used but not"
                                          " defined; did you mean load-metric?"))))))

;; A lab of workstations, which needs no simulator, and two tasks: one
;; that troy takes, and one that nobody can.
(define demo-lab
  (make-test-lab '((aspace troy (capabilities camera)) (aspace praline))
                 '(("camera.scm" . "(list 'snap 1 (list (list '() (list 'camera)))
                                         (list #f) (list (lambda () 'snapped)))\n")
                   ("laser.scm" . "(list 'scan 1 (list (list '() (list 'laser)))
                                        (list #f) (list (lambda () 'scanned)))\n"))))

;; (exit-status whole-output) of `bin/murdoch demo` posing task, run in
;; the lab's folder, where the view writes runs/.
(define (demo task)
  (let* ((lab-dir (test-lab-directory demo-lab))
         (status (system "sh" "-c"
                         (string-append "cd \"$1\" && MURDOCH_DEMO_TASK=\"$1/$2\""
                                        " timeout -s KILL 200 \"$0/bin/murdoch\""
                                        " demo lab.scm >demo.out 2>&1")
                         (tool-path ".") lab-dir task)))
    (list (quotient (if (pair? status) (cadr status) status) 256)
          (file-text (string-append lab-dir "/demo.out")))))

;; The tasks of the last snapshot of the trace that the demo's output
;; names, as a list, or #f.
(define (last-snapshot-tasks output)
  (let* ((line (find (lambda (l) (text-contains? l "replay the run in the browser: "))
                     (text-lines output)))
         (path (and line (last-word line)))
         (trace (and path (if (char=? #\/ (string-ref path 0))
                              path
                              (string-append (test-lab-directory demo-lab) "/" path)))))
    (and trace (file-exists? trace)
         (vector->list (cdr (assq 'tasks (string->json (last (read-lines trace)))))))))

(define (last-word line)
  (let loop ((i (string-length line)))
    (cond ((zero? i) line)
          ((char=? #\space (string-ref line (- i 1)))
           (substring line i (string-length line)))
          (else (loop (- i 1))))))

(test-group "demo: its output, always, and its exit status"
  (let ((r (demo "camera.scm")))
    (test "a task done: exit 0" 0 (status r))
    (test "the pose's output is shown, to its result" #t
      (text-contains? (cadr r) "(snapped)"))
    (test "and no file is read before it is made" #f
      (text-contains? (cadr r) "No such file"))
    ;; troy's component holds no subject and is over at once: the view
    ;; sees it by what troy says ended there, and the demo stops the lab
    ;; once the view has looked after the pose's end.
    (test "its replay ends on the task done, and who won its component"
        '("snap" "done" ((1 "troy" "done")))
      (let ((last-tasks (last-snapshot-tasks (cadr r))))
        (and (pair? last-tasks)
             (let ((t (car last-tasks)))
               (list (cdr (assq 'name t)) (cdr (assq 'state t))
                     (map (lambda (c)
                            (map (lambda (k) (cdr (assq k c))) '(index robot end)))
                          (vector->list (cdr (assq 'components t))))))))))
  (let ((r (demo "laser.scm")))
    (test "a task nobody takes: exit non-zero" #t (positive? (status r)))
    (test "its output is shown" #t (text-contains? (cadr r) "not-enough-takers"))
    (test "and the demo says so" #t
      (text-contains? (cadr r) "the task did not complete")))
  ;; troy's port is taken: the lab stops at once, and the demo, which
  ;; watches its child by /proc rather than kill -0, says so and ends.
  (let* ((squatter (make-listener-socket
                    (get-address-info "127.0.0.1" (test-lab-port-base demo-lab)) 5))
         (r (demo "camera.scm")))
    (close-port (open-input-file-descriptor squatter))
    (test "a lab that cannot start: exit non-zero" #t (positive? (status r)))
    (test "and the demo says so, with the lab's word on it" '(#t #t)
      (list (text-contains? (cadr r) "demo: the lab did not start")
            (text-contains? (cadr r) "troy died")))))

(test-end)
(remove-test-lab! demo-lab)
(delete-file-hierarchy dir)
(test-exit)
