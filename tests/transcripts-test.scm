;;; Replays every tests/transcripts/*.txt against a fresh lab of its own
;;; (docs/transcripts.md): `bin/murdoch lab` on a free port base, then
;;; `bin/murdoch repl` with the transcript's input piped in.
(import (scheme base) (scheme char) (scheme write) (scheme file) (srfi 1) (chibi test)
        (only (chibi filesystem) directory-files delete-file-hierarchy)
        (only (chibi process) system? call-with-process-io waitpid)
        (murdoch testing) (murdoch transcript))

(define (transcript-files)
  (let ((dir (tool-path "tests/transcripts")))
    (map (lambda (f) (string-append dir "/" f))
         (sort-strings (filter (lambda (f) (string-suffix? ".txt" f))
                               (directory-files dir))))))

(define (string-suffix? suffix s)
  (let ((n (string-length s)) (k (string-length suffix)))
    (and (>= n k) (string=? suffix (substring s (- n k) n)))))

(define (sort-strings ls)
  (if (null? ls)
      '()
      (let ((pivot (car ls)))
        (append (sort-strings (filter (lambda (s) (string<? s pivot)) (cdr ls)))
                (list pivot)
                (sort-strings (remove (lambda (s) (string<? s pivot)) (cdr ls)))))))

(define (write-text file text)
  (call-with-output-file file (lambda (out) (write-string text out))))

;; The lab of transcript t, started in dir on a free port base without the
;; address space the REPL will be, if it is one of the lab's; answers
;; (pid . port-base) once it is ready.
(define (start-lab! t dir)
  (let ((base (free-port-base dir)))
    (cons (start-murdoch-lab!
           (cons* (tool-path (transcript-lab t)) "--logs" (string-append dir "/logs")
                  (if (transcript-as t)
                      (list "--except" (symbol->string (transcript-as t)))
                      '()))
           (string-append dir "/lab.out")
           base)
          (number->string base))))

;; The REPL's whole output for t's input, stdout and stderr together.
;; Its input is typed through a pipe, a line at a time, so that a shell
;; command runs only once the REPL has answered every input before it.
(define (replay t dir base lab-pid)
  (let ((out (string-append dir "/output")))
    (call-with-process-io
     (list "sh" "-c"
           "MURDOCH_PORT_BASE=$1 exec timeout -s KILL 90 \"$2\" repl \"$3\" $4 >\"$5\" 2>&1"
           "replay" base (tool-path "bin/murdoch") (tool-path (transcript-lab t))
           (if (transcript-as t) (symbol->string (transcript-as t)) "")
           out)
     (lambda (pid in . _)
       (for-each (lambda (item) (perform! item t in out base lab-pid))
                 (transcript-script t))
       (close-output-port in)
       (waitpid pid 0)))
    (file-text out)))

;; An input line is typed; a shell command waits for the REPL's answers
;; (at most 60 s), then runs with LAB_PID and MURDOCH_PORT_BASE set.
(define (perform! item t in out base lab-pid)
  (cond
   ((string? item)
    (write-string (string-append item "\n") in)
    (flush-output-port in))
   (else
    (let ((k (car (cddr item))))
      (wait-until 60 (lambda ()
                       (let ((output (file-text out)))
                         (> (prompt-count (prompt-of t output) output) k))))
      (system? "env" (string-append "LAB_PID=" (number->string lab-pid))
               (string-append "MURDOCH_PORT_BASE=" base)
               "sh" "-c" (cadr item))))))

;; The REPL's prompt: its uid, which for a guest holds its process id.
(define (prompt-of t output)
  (if (transcript-as t)
      (string-append (symbol->string (transcript-as t)) "> ")
      (guest-prompt output)))

(define (guest-prompt output)
  (let loop ((i 0))
    (cond ((> (+ i 6) (string-length output)) "guest-?> ")
          ((string=? "guest-" (substring output i (+ i 6)))
           (let digits ((j (+ i 6)))
             (if (and (< j (string-length output))
                      (char-numeric? (string-ref output j)))
                 (digits (+ j 1))
                 (string-append (substring output i j) "> "))))
          (else (loop (+ i 1))))))

;; A diff of each mismatch: the input, "-" before the lines expected and
;; "+" before those the REPL printed.
(define (report file mismatches output)
  (if (pair? mismatches)
      (begin
        (display (string-append "transcript " file " differs:\n"))
        (for-each report-mismatch mismatches)
        (display "the REPL's whole output:\n")
        (display output)
        (newline))))

(define (report-mismatch m)
  (let ((field (lambda (key) (cadr (memq key m)))))
    (if (memq 'input m)
        (begin
          (display (string-append "> " (field 'input) "\n"))
          (for-each (lambda (l) (display (string-append "- " l "\n"))) (field 'expected))
          (for-each (lambda (l) (display (string-append "+ " l "\n"))) (field 'actual)))
        (begin (write m) (newline)))))

;; A transcript that cannot be read or whose lab does not start fails as
;; a test (chibi test reports the error) rather than ending the run.
(define (check-transcript file)
  (let ((dir (temporary-directory)))
    (test file '() (mismatches-of file (read-transcript file) dir))
    (delete-file-hierarchy dir)))

(define (mismatches-of file t dir)
  (let ((lab (start-lab! t dir)))
    (dynamic-wind
     (lambda () #f)
     (lambda ()
       (let* ((output (replay t dir (cdr lab) (car lab)))
              (mismatches (transcript-mismatches t (prompt-of t output) output)))
         (report file mismatches output)
         mismatches))
     (lambda () (stop-process! (car lab))))))

(test-begin "transcripts")
(for-each check-transcript (transcript-files))
;; The REPL sessions of the tutorial and the README, replayed as they are
;; written there, so that neither drifts from the code.
(for-each (lambda (doc)
            (let ((dir (temporary-directory)))
              (test doc '() (mismatches-of doc (read-doc-transcript (tool-path doc)) dir))
              (delete-file-hierarchy dir)))
          '("docs/tutorial.md" "README.md"))
(test-end)
(test-exit)
