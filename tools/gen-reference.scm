;;; tools/gen-reference.scm: writes docs/reference.md on its standard
;;; output -- every export of (murdoch), with its arguments, the first
;;; sentence of its ;;> comment, and the part of the thesis's appendix
;;; that defines the thesis's own version (docs/thesis-map.md).
;;;
;;;   tools/chibi tools/gen-reference.scm > docs/reference.md
;;;
;;; Each name's comment is read from the library that defines it: the
;;; first of (murdoch)'s imports to export it, or, when that one only
;;; passes it on, the first of its own imports to.
;;; tests/reference-test.scm fails when docs/reference.md is not what
;;; this writes, and when an export has no comment.
(import (scheme base) (scheme write) (scheme read) (scheme file) (scheme char)
        (scheme process-context)
        (srfi 1) (only (chibi string) string-join) (only (chibi pathname) path-directory))

(define top (or (get-environment-variable "MURDOCH_TOP") "."))

;; Library forms are read once each.
(define forms '())
(define (read-form file)
  (cond ((assoc file forms) => cdr)
        (else (let ((form (call-with-input-file file read)))
                (set! forms (cons (cons file form) forms))
                form))))

(define (declarations form key)
  (append-map (lambda (d) (if (and (pair? d) (eq? (car d) key)) (cdr d) '()))
              (cddr form)))

;; (INTERNAL . EXTERNAL) for each name a library's export list gives.
(define (export-pairs form)
  (map (lambda (e) (if (pair? e) (cons (cadr e) (car (cddr e))) (cons e e)))
       (declarations form 'export)))

(define (import-library set)
  (if (memq (car set) '(only except rename prefix)) (import-library (cadr set)) set))

(define (ours? name) (and (pair? name) (eq? (car name) 'murdoch) (pair? (cdr name))))

(define (library-path name)
  (string-join (map symbol->string name) "/"))

(define (library-file name)
  (string-append top "/lib/" (library-path name) ".sld"))

(define murdoch-form (read-form (string-append top "/lib/murdoch.sld")))

;; The ;;> comments of library name: (NAME SIGNATURE TEXT) for each
;; definition a comment stands right above (other ; lines may come
;; between), in the .sld and the files it includes.  (chibi doc)'s
;; extract-module-docs was tried first: it gives some one-line
;; definitions the name of the definition before them (local-aspace-uid
;; as aspace-started-at, remote-timeout as set-remote-timeout!).
(define docs-cache '())
(define (library-docs name)
  (cond
   ((assoc name docs-cache) => cdr)
   (else
    (let* ((sld (library-file name))
           (files (cons sld (map (lambda (f) (string-append (path-directory sld) "/" f))
                                 (declarations (read-form sld) 'include))))
           (docs (append-map file-docs files)))
      (set! docs-cache (cons (cons name docs) docs-cache))
      docs))))

(define (file-lines path)
  (call-with-input-file path
    (lambda (in)
      (let loop ((acc '()))
        (let ((line (read-line in)))
          (if (eof-object? line) (reverse acc) (loop (cons line acc))))))))

(define (trim-left s)
  (let loop ((i 0))
    (if (and (< i (string-length s)) (char-whitespace? (string-ref s i)))
        (loop (+ i 1))
        (substring s i (string-length s)))))

(define (doc-line? line) (string-prefix? ";;>" (trim-left line)))

(define (doc-text line)
  (let ((s (substring (trim-left line) 3 (string-length (trim-left line)))))
    (if (string-prefix? " " s) (substring s 1 (string-length s)) s)))

(define (file-docs path)
  (let loop ((lines (file-lines path)) (doc '()) (acc '()))
    (cond
     ((null? lines) (reverse acc))
     ((doc-line? (car lines))
      (loop (cdr lines) (cons (doc-text (car lines)) doc) acc))
     ((and (pair? doc) (string-prefix? ";" (trim-left (car lines))))
      (loop (cdr lines) doc acc))
     ((string-prefix? "(define-record-type " (car lines))
      (loop (cdr lines) '() (append (reverse (record-entries lines)) acc)))
     ((or (string-prefix? "(define" (car lines))
          (and (pair? doc) (string-prefix? "(define" (trim-left (car lines)))))
      (let ((entry (definition-entry (definition-head lines) (reverse doc))))
        (loop (cdr lines) '() (if entry (cons entry acc) acc))))
     (else (loop (cdr lines) '() acc)))))

;; A record type's procedures: (NAME NAME TEXT) each, TEXT the ;;>
;; comment right above the line of the form that names it ("" when none).
(define (record-entries lines)
  (let* ((form-lines (take lines (min 40 (length lines))))
         (form (guard (e (#t #f))
                 (read (open-input-string
                        (apply string-append
                               (map (lambda (l) (string-append l "\n")) form-lines)))))))
    (if (and (list? form) (>= (length form) 3))
        (map (lambda (name)
               (list name (symbol->string name) (field-doc name (cdr form-lines))))
             (filter symbol?
                     (append (if (pair? (list-ref form 2)) (list (car (list-ref form 2))) '())
                             (if (> (length form) 3) (list (list-ref form 3)) '())
                             (append-map (lambda (f) (if (pair? f) (cdr f) '()))
                                         (if (> (length form) 4) (drop form 4) '())))))
        '())))

;; The ;;> lines right above the first of lines that names name.
(define (field-doc name lines)
  (let loop ((lines lines) (doc '()))
    (cond ((null? lines) "")
          ((doc-line? (car lines)) (loop (cdr lines) (cons (doc-text (car lines)) doc)))
          ((names? (car lines) name)
           (squeeze (apply string-append (map (lambda (l) (string-append l "\n")) (reverse doc)))))
          (else (loop (cdr lines) '())))))

;; Whether line has name as a whole word, before any comment.
(define (names? line name)
  (let ((words (guard (e (#t '()))
                 (let ((in (open-input-string line)))
                   (let loop ((acc '()))
                     (let ((x (read in)))
                       (if (eof-object? x) acc (loop (cons x acc)))))))))
    (any (lambda (w) (or (eq? w name) (and (pair? w) (memq name w) #t))) words)))

;; The head of the definition that starts lines: (define NAME-OR-FORMALS)
;; or (define-syntax NAME TRANSFORMER), the transformer when its first
;; rule is within a few lines, else #f.
(define (definition-head lines)
  (let ((in (open-input-string
             (apply string-append (map (lambda (l) (string-append l "\n"))
                                       (take lines (min 8 (length lines))))))))
    (read-char in)
    (let* ((head (read in))
           (target (read in))
           (more (guard (e (#t #f)) (read in))))
      (list head target (if (eof-object? more) #f more)))))

(define (written x)
  (let ((out (open-output-string))) (write x out) (get-output-string out)))

;; (NAME SIGNATURE TEXT) of a definition and its comment's lines.
(define (definition-entry form doc)
  (let ((text (squeeze (apply string-append (map (lambda (l) (string-append l "\n")) doc)))))
    (and (pair? form) (pair? (cdr form))
         (case (car form)
           ((define)
            (if (pair? (cadr form))
                (list (car (cadr form)) (written (cadr form)) text)
                (list (cadr form) (symbol->string (cadr form)) text)))
           ((define-syntax)
            (let* ((rules (and (pair? (cddr form)) (car (cddr form))))
                   (pattern (and (pair? rules) (eq? (car rules) 'syntax-rules)
                                 (pair? (cddr rules)) (pair? (car (cddr rules)))
                                 (car (car (cddr rules))))))
              (list (cadr form) (if pattern (written pattern) (symbol->string (cadr form)))
                    text)))
           (else #f)))))

;; Where name is documented, starting from library lib: (LIB SIGNATURE
;; TEXT) or #f.
(define (find-docs lib name seen)
  (and (ours? lib) (not (member lib seen)) (file-exists? (library-file lib))
       (let ((form (read-form (library-file lib))))
         (and (assq name (export-pairs form))
              (or (let ((d (or (find (lambda (d) (and (eq? (car d) name)
                                                       (> (string-length (car (cddr d))) 0)))
                                     (library-docs lib))
                               (assq name (library-docs lib)))))
                    (and d (list lib (cadr d) (car (cddr d)))))
                  (any (lambda (i) (find-docs i name (cons lib seen)))
                       (map import-library (declarations form 'import))))))))

;; The library that exports name first, for an undocumented name.
(define (exporter name)
  (find (lambda (lib)
          (and (ours? lib) (file-exists? (library-file lib))
               (assq name (export-pairs (read-form (library-file lib))))))
        (map import-library (declarations murdoch-form 'import))))

;;; Text

;; The comment's Scribble, \\var{x} and \\scheme{x}, as Markdown's `x`.
(define (markdown s)
  (let loop ((cs (string->list s)) (acc '()))
    (cond
     ((null? cs) (list->string (reverse acc)))
     ((and (char=? (car cs) #\\) (scribble-command cs))
      => (lambda (rest+word)
           (loop (cdr rest+word) (append (reverse (string->list (string-append "`" (car rest+word) "`"))) acc))))
     (else (loop (cdr cs) (cons (car cs) acc))))))

;; For \\NAME{TEXT} at the head of cs: (TEXT . the chars after), else #f.
(define (scribble-command cs)
  (let* ((name (take-while char-alphabetic? (cdr cs)))
         (rest (drop (cdr cs) (length name))))
    (and (pair? name) (pair? rest) (char=? (car rest) #\{)
         (let ((close (list-index (lambda (c) (char=? c #\})) (cdr rest))))
           (and close
                (cons (list->string (take (cdr rest) close))
                      (drop (cdr rest) (+ close 1))))))))

;; White space as one space; a word broken at a hyphen across lines whole.
(define (squeeze s)
  (let loop ((cs (string->list s)) (acc '()) (space? #t))
    (cond ((null? cs) (list->string (reverse (if (and (pair? acc) (char=? (car acc) #\space)) (cdr acc) acc))))
          ((char-whitespace? (car cs))
           (loop (cdr cs)
                 (if (or space? (and (pair? acc) (pair? (cdr acc)) (char=? (car acc) #\-)
                                     (char-alphabetic? (cadr acc))))
                     acc
                     (cons #\space acc))
                 #t))
          (else (loop (cdr cs) (cons (car cs) acc) #f)))))

;; Up to the first full stop that ends a sentence, outside `code` and
;; parentheses.
(define (first-sentence s)
  (let ((n (string-length s)))
    (let loop ((i 0) (code? #f) (depth 0))
      (if (>= i n)
          s
          (let ((c (string-ref s i)))
            (cond ((char=? c #\`) (loop (+ i 1) (not code?) depth))
                  (code? (loop (+ i 1) code? depth))
                  ((char=? c #\() (loop (+ i 1) code? (+ depth 1)))
                  ((char=? c #\)) (loop (+ i 1) code? (max 0 (- depth 1))))
                  ((and (char=? c #\.) (zero? depth)
                        (or (= (+ i 1) n) (char=? (string-ref s (+ i 1)) #\space))
                        (not (abbreviation? s i)))
                   (substring s 0 (+ i 1)))
                  (else (loop (+ i 1) code? depth))))))))

(define (abbreviation? s i)
  (any (lambda (a) (let ((k (string-length a)))
                     (and (>= (+ i 1) k) (string=? a (substring s (- (+ i 1) k) (+ i 1))))))
       '("e.g." "i.e." "etc." "cf.")))

(define (cell s)
  (list->string (append-map (lambda (c) (if (char=? c #\|) (list #\\ #\|) (list c)))
                            (string->list s))))

;;; The thesis map: name -> "A.N file.scm"

(define (string-prefix? p s)
  (and (>= (string-length s) (string-length p)) (string=? p (substring s 0 (string-length p)))))

(define (row-cells line)
  (let loop ((cs (string->list line)) (cell '()) (cells '()))
    (cond ((null? cs) (reverse cells))
          ((char=? (car cs) #\|) (loop (cdr cs) '() (cons (squeeze (list->string (reverse cell))) cells)))
          (else (loop (cdr cs) (cons (car cs) cell) cells)))))

(define thesis-map
  (call-with-input-file (string-append top "/docs/thesis-map.md")
    (lambda (in)
      (let loop ((acc '()))
        (let ((line (read-line in)))
          (if (eof-object? line)
              (reverse acc)
              (let ((cells (row-cells line)))
                (loop (if (and (= (length cells) 5) (string-prefix? "A." (list-ref cells 1))
                               (string-prefix? "`" (list-ref cells 2)))
                          (let ((name (list-ref cells 2)))
                            (cons (cons (string->symbol (substring name 1 (- (string-length name) 1)))
                                        (list-ref cells 1))
                                  acc))
                          acc)))))))))


;;; The page

;; The signature users write: under the exported name, when (murdoch)
;; renames it.
(define (signature-of external internal sig)
  (let ((old (symbol->string internal))
        (new (symbol->string external)))
    (cond ((not sig) new)
          ((string=? sig old) new)
          ((string-prefix? (string-append "(" old " ") sig)
           (string-append "(" new (substring sig (+ 1 (string-length old)) (string-length sig))))
          ((string=? sig (string-append "(" old ")")) (string-append "(" new ")"))
          (else sig))))

(define (lib-text lib) (string-append "lib/" (library-path lib) ".scm"))

(define (main)
  (let* ((entries
          (map (lambda (p)
                 (let ((d (find-docs* (car p))))
                   (list (cdr p) (car p) d)))
               (export-pairs murdoch-form)))
         (libraries (delete-duplicates
                     (map (lambda (e) (if (car (cddr e)) (car (car (cddr e))) (exporter (cadr e))))
                          entries))))
    (display "# Reference: the (murdoch) library\n\n")
    (display "Every name that `(murdoch)` exports -- what user code, and code sent to\n")
    (display "a robot, can use -- with its arguments and the first sentence of its\n")
    (display "`;;>` comment, grouped by the library that defines it; the source has the\n")
    (display "rest.  The thesis column names the file of the thesis's appendix that\n")
    (display "defines the thesis's own version (docs/thesis-map.md); a name without\n")
    (display "one is Murdoch's own.\n\n")
    (display "Generated by `tools/chibi tools/gen-reference.scm > docs/reference.md`;\n")
    (display "`tests/reference-test.scm` fails when this page is out of date.\n")
    (for-each
     (lambda (lib)
       (display (string-append "\n## " (lib-text lib) "\n\n"))
       (display "| name | meaning | thesis |\n| --- | --- | --- |\n")
       (for-each
        (lambda (e)
          (let* ((external (car e)) (internal (cadr e)) (d (car (cddr e))))
            (when (equal? lib (if d (car d) (exporter internal)))
              (display
               (string-append
                "| `" (cell (signature-of external internal (and d (cadr d)))) "` | "
                (cell (if (and d (> (string-length (car (cddr d))) 0))
                          (first-sentence (markdown (car (cddr d))))
                          "(no `;;>` comment yet)"))
                " | "
                (cond ((assq internal thesis-map) => cdr)
                      ((assq external thesis-map) => cdr)
                      (else ""))
                " |\n")))))
        entries))
     libraries)
    (display tasks-epilogue)))

;; What the first sentences leave out of the tasks' procedures, and
;; `murdoch pose`'s task file, written here once.
(define tasks-epilogue "
## Tasks: start-task's keywords, a task's word, murdoch pose's task file

`(start-task NAME N CAPABILITIES METRICS PROCEDURES [PRIORITIES
[RESTARTABLE]] KEYWORD VALUE ...)`: pose-task's arguments, then optionally
the components' priorities and a list of a boolean for each component (may
it move to another robot when its robot is lost), then keywords
(docs/tasks.md):

| keyword | value | default |
| --- | --- | --- |
| wait | `#t`: wait while too few capable robots are free; `#f`: fail at once with `not-enough-takers` | the lab's `when-robots-busy` |
| hold | `#t`: wait, keeping the robots won for some components | `#f` |
| priority | a number, 0 or more; the higher goes first | `(pose-task-priority)` |
| deadline | seconds: a task not started by then ends as `deadline` | none |

`task-state` is one word: `negotiating`, `waiting`, `holding`, `running`,
then `done` (every component completed), `failed` (`task-why` says why:
the first failure's), `cancelled` or `deadline`.  `(tasks)` lists the
tasks this address space started that are not over, and the newest
`tasks-kept` (a lab setting, 20) of those over, as `(posed ID STATE WHY
PLACE PRIORITY HELD WANTS)`, and each component it runs as `(running ID
INDEX POSER)`.

`murdoch pose LAB FILE` reads FILE as the REPL would and takes the value
of its last form: pose-task's arguments, which it starts as `start-task`
does; a task already started (`start-task`, `start-steps`), which it
waits for; or, when the last form defines a procedure of no arguments,
what that procedure answers.  It prints pose-task's progress, the task's
results, and a last line `murdoch pose: ID WORD` (`failed: WHY` for a
failed task).  It exits 0 when the task is done, 1 when it is not, 130
after Ctrl-C and 143 after SIGTERM: either cancels the task, so that its
robots stop where they are and free their subjects, as Ctrl-C at a REPL
gives its components up; a second one ends the pose at once.
")

(define (find-docs* name)
  (any (lambda (lib) (find-docs lib name '()))
       (map import-library (declarations murdoch-form 'import))))

(main)
