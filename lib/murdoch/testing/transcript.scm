;;;; Transcripts: what to type at a REPL, and what it should answer.

(define-record-type transcript
  (make-transcript lab as steps shell)
  transcript?
  (lab transcript-lab)          ; the lab file, relative to the repository
  (as transcript-as)            ; the address space to join as, or #f
  (steps transcript-steps)      ; ((input expected-line ...) ...)
  (shell transcript-shell))     ; ((K . command) ...): run after K inputs

(define (prefixed? prefix line)
  (and (>= (string-length line) (string-length prefix))
       (string=? prefix (substring line 0 (string-length prefix)))))

(define (after prefix line)
  (string-trim (substring line (string-length prefix) (string-length line))))

(define (string-trim s)
  (let loop ((i 0) (j (string-length s)))
    (cond ((and (< i j) (char-whitespace? (string-ref s i))) (loop (+ i 1) j))
          ((and (< i j) (char-whitespace? (string-ref s (- j 1)))) (loop i (- j 1)))
          (else (substring s i j)))))

;;> Reads transcript \var{file}: ";;" and blank lines dropped, "lab:" and
;;> "as:" the header, "> " lines input followed by what they print, "$ "
;;> a shell command run once the REPL answered the inputs before it.
(define (read-transcript file)
  (let loop ((lines (read-lines file)) (lab #f) (as #f) (steps '()) (shell '()))
    (cond
     ((null? lines)
      (if (not lab) (error "a transcript needs a lab: line" file))
      (make-transcript lab as (reverse (map reverse steps)) (reverse shell)))
     (else
      (let ((line (car lines)) (rest (cdr lines)))
        (cond
         ((or (prefixed? ";;" line) (string=? "" (string-trim line)))
          (loop rest lab as steps shell))
         ((and (null? steps) (prefixed? "lab:" line))
          (loop rest (after "lab:" line) as steps shell))
         ((and (null? steps) (prefixed? "as:" line))
          (loop rest lab (string->symbol (after "as:" line)) steps shell))
         ((prefixed? "> " line)
          (loop rest lab as (cons (list (after "> " line)) steps) shell))
         ((prefixed? "$ " line)
          (loop rest lab as steps
                (cons (cons (length steps) (after "$ " line)) shell)))
         ((null? steps) (error "output before any input" file line))
         ((and (pair? shell) (= (caar shell) (length steps)))
          (error "output after a shell command, which is not compared" file line))
         (else
          (loop rest lab as (cons (cons line (car steps)) (cdr steps))
                shell))))))))

;;> A document's REPL sessions as one transcript: code blocks that start
;;> with a prompt, at the lab "<!-- transcript lab: FILE -->" names; a
;;> number matches any number, "..." any text.
(define (read-doc-transcript file)
  (let ((lines (read-lines file)))
    (make-transcript
     (or (any (lambda (l) (and (prefixed? "<!-- transcript lab: " l)
                               (string-trim (substring l 21 (- (string-length l) 4)))))
              lines)
         (error "a document to replay names its lab" file))
     #f
     (append-map block-steps (code-blocks lines))
     '())))

;; The code blocks of markdown lines: fenced by ``` or indented four spaces.
(define (code-blocks lines)
  (let loop ((lines lines) (blocks '()))
    (cond
     ((null? lines) (reverse blocks))
     ((prefixed? "```" (car lines))
      (let ((end (or (list-index (lambda (l) (prefixed? "```" l)) (cdr lines))
                     (length (cdr lines)))))
        (loop (drop (cdr lines) (min (+ end 1) (length (cdr lines))))
              (cons (take (cdr lines) end) blocks))))
     ((prefixed? "    " (car lines))
      (let-values (((block rest) (span (lambda (l) (prefixed? "    " l)) lines)))
        (loop rest (cons (map (lambda (l) (substring l 4 (string-length l))) block)
                         blocks))))
     (else (loop (cdr lines) blocks)))))

(define (prompt-end line)
  (let loop ((i 0))
    (cond ((>= (+ i 1) (string-length line)) #f)
          ((and (char=? (string-ref line i) #\>)
                (char=? (string-ref line (+ i 1)) #\space))
           (and (> i 0) i))
          ((or (char-alphabetic? (string-ref line i)) (char-numeric? (string-ref line i))
               (char=? (string-ref line i) #\-))
           (loop (+ i 1)))
          (else #f))))

(define (block-steps block)
  (if (and (pair? block) (prompt-end (car block)))
      (let loop ((lines block) (steps '()))
        (cond ((null? lines) (reverse (map reverse steps)))
              ((prompt-end (car lines))
               => (lambda (i)
                    (loop (cdr lines)
                          (cons (list (substring (car lines) (+ i 2)
                                                 (string-length (car lines))))
                                steps))))
              (else (loop (cdr lines)
                          (cons (cons (loosen (car lines)) (car steps)) (cdr steps))))))
      '()))

(define (loosen line)
  (let loop ((i 0) (acc '()))
    (cond
     ((= i (string-length line)) (apply string-append (reverse acc)))
     ((and (<= (+ i 3) (string-length line)) (string=? "..." (substring line i (+ i 3))))
      (loop (+ i 3) (cons "{any}" acc)))
     ((number-start? line i)
      (let ((end (number-end line i)))
        (loop end (cons "{number}" acc))))
     (else (loop (+ i 1) (cons (string (string-ref line i)) acc))))))

(define (digit-at? line i)
  (and (< i (string-length line)) (char-numeric? (string-ref line i))))

(define (number-start? line i)
  (or (digit-at? line i)
      (and (char=? (string-ref line i) #\-) (digit-at? line (+ i 1)))))

(define (number-end line i)
  (let loop ((j (+ i 1)))
    (if (and (< j (string-length line))
             (or (char-numeric? (string-ref line j))
                 (and (char=? (string-ref line j) #\.) (digit-at? line (+ j 1)))))
        (loop (+ j 1))
        j)))

;;> What to do: input lines, and (shell COMMAND K) to run after K answers.
(define (transcript-script t)
  (let loop ((k 0) (steps (transcript-steps t)) (shell (transcript-shell t)))
    (cond ((and (pair? shell) (= k (caar shell)))
           (cons (list 'shell (cdar shell) k) (loop k steps (cdr shell))))
          ((pair? steps)
           (cons (caar steps) (loop (+ k 1) (cdr steps) shell)))
          (else '()))))

;;> The mismatches between the REPL's \var{output} and \var{t}; empty when none.
(define (transcript-mismatches t prompt output)
  (let ((answers (split-at-prompts output prompt))
        (steps (transcript-steps t)))
    (if (not (= (length answers) (+ 1 (length steps))))
        (list (list 'prompts-expected (+ 1 (length steps))
                    'prompts-seen (length answers)))
        (append-map step-mismatches steps (take answers (length steps))))))

;;> How many times \var{prompt} is in \var{output}: one more than the inputs answered.
(define (prompt-count prompt output)
  (length (split-at-prompts output prompt)))

;; What the REPL printed after each prompt, as lists of lines.
(define (split-at-prompts output prompt)
  (let loop ((start (string-search prompt output 0)) (acc '()))
    (if (not start)
        (reverse acc)
        (let* ((from (+ start (string-length prompt)))
               (next (string-search prompt output from)))
          (loop next
                (cons (text-lines (substring output from
                                             (or next (string-length output))))
                      acc))))))

(define (text-lines text)
  (let loop ((i 0) (start 0) (acc '()))
    (cond ((= i (string-length text))
           (reverse (if (= start i) acc (cons (substring text start i) acc))))
          ((char=? #\newline (string-ref text i))
           (loop (+ i 1) (+ i 1) (cons (substring text start i) acc)))
          (else (loop (+ i 1) start acc)))))

(define (string-search pattern text from)
  (let ((n (string-length pattern)) (end (string-length text)))
    (let loop ((i from))
      (cond ((> (+ i n) end) #f)
            ((string=? pattern (substring text i (+ i n))) i)
            (else (loop (+ i 1)))))))

(define (step-mismatches step actual)
  (let ((expected (cdr step)))
    (if (and (= (length expected) (length actual))
             (every line-matches? expected actual))
        '()
        (list (list 'input (car step) 'expected expected 'actual actual)))))

;;> True when \var{line} matches \var{pattern}: text matches itself,
;;> \scheme{{number}} a number as Scheme writes it, \scheme{{any}} any text.
(define (line-matches? pattern line)
  (let match ((p 0) (l 0))
    (cond
     ((= p (string-length pattern)) (= l (string-length line)))
     ((placeholder-at pattern p "{any}")
      => (lambda (p*) (any (lambda (l*) (match p* l*))
                           (iota (+ 1 (- (string-length line) l)) l))))
     ((placeholder-at pattern p "{number}")
      => (lambda (p*) (any (lambda (l*) (match p* l*))
                           (number-ends line l))))
     ((and (< l (string-length line))
           (char=? (string-ref pattern p) (string-ref line l)))
      (match (+ p 1) (+ l 1)))
     (else #f))))

(define (placeholder-at pattern p name)
  (let ((end (+ p (string-length name))))
    (and (<= end (string-length pattern))
         (string=? name (substring pattern p end))
         end)))

;; Every end e such that line[l, e) reads as a number.
(define (number-ends line l)
  (filter (lambda (e)
            (string->number (substring line l e)))
          (iota (- (string-length line) l) (+ l 1))))

;;; Replaying: bin/murdoch lab, then bin/murdoch repl fed through a pipe.

;; Starts t's lab in dir on a free port base; answers (pid . port-base).
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

;; The REPL's whole output for t's input, typed a line at a time.
(define (replay t dir base lab-pid)
  (let ((out (string-append dir "/output")))
    (call-with-process-io
     (list "sh" "-c"
           (string-append "MURDOCH_PORT_BASE=$1 exec timeout -s KILL 90"
                          " \"$2\" repl \"$3\" $4 >\"$5\" 2>&1")
           "replay" base (tool-path "bin/murdoch") (tool-path (transcript-lab t))
           (if (transcript-as t) (symbol->string (transcript-as t)) "")
           out)
     (lambda (pid in . _)
       (for-each (lambda (item) (perform! item t in out base lab-pid))
                 (transcript-script t))
       (close-output-port in)
       (waitpid pid 0)))
    (file-text out)))

;; Types an input line; a shell command waits for the REPL (60 s at most).
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

;; A diff of each mismatch: the input, "-" expected lines, "+" printed ones.
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

;;> Replays transcript \var{t} from \var{file} against a fresh lab, as one
;;> test named \var{file}, showing a mismatch as a diff.
(define (check-transcript file t)
  (let ((dir (temporary-directory)))
    (test file '() (mismatches-of file t dir))
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
