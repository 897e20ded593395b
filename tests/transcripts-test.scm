;;; Replays every tests/transcripts/*.txt against a fresh lab of its own
;;; (docs/transcripts.md): `bin/murdoch lab` on a free port base, then
;;; `bin/murdoch repl` with the transcript's input piped in.
(import (scheme base) (scheme char) (scheme write) (scheme file) (srfi 1) (chibi test)
        (only (chibi filesystem) directory-files delete-file-hierarchy)
        (only (chibi process) system?)
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
  (let ((base (free-port-base)))
    (cons (start-murdoch-lab!
           (cons* (tool-path (transcript-lab t)) "--logs" (string-append dir "/logs")
                  (if (transcript-as t)
                      (list "--except" (symbol->string (transcript-as t)))
                      '()))
           (string-append dir "/lab.out")
           base)
          (number->string base))))

;; The REPL's whole output for t's input, stdout and stderr together.
(define (replay t dir base)
  (let ((in (string-append dir "/input")) (out (string-append dir "/output")))
    (write-text in (transcript-input t))
    (system? "sh" "-c"
             "MURDOCH_PORT_BASE=$1 timeout -s KILL 60 \"$2\" repl \"$3\" $4 <\"$5\" >\"$6\" 2>&1"
             "replay" base (tool-path "bin/murdoch") (tool-path (transcript-lab t))
             (if (transcript-as t) (symbol->string (transcript-as t)) "")
             in out)
    (file-text out)))

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
       (let* ((output (replay t dir (cdr lab)))
              (mismatches (transcript-mismatches t (prompt-of t output) output)))
         (report file mismatches output)
         mismatches))
     (lambda () (stop-process! (car lab))))))

(test-begin "transcripts")
(for-each check-transcript (transcript-files))
(test-end)
(test-exit)
