;;; The murdoch command: see `bin/murdoch --help`.
;;
;; One table of commands; (chibi app) parses each command's options, as its
;; conventions have them, and this side says, in one line and the usage,
;; what is wrong with a command line, exiting 2: a user's mistake is no
;; occasion for a stack trace.
(import (scheme base) (scheme write) (scheme process-context) (scheme eval) (srfi 1)
        (chibi app) (chibi config) (chibi edit-distance)
        (only (chibi pathname) path-directory)
        (only (chibi ast) setenv unsetenv)
        (only (murdoch wire) error-message error-message-naming) (murdoch lab)
        (murdoch cli))

(define version "0.3")

;; The sh scripts that supervise processes live beside this file.
(define bin (path-directory (car (command-line))))

;; (chibi app) reads "--except a" as a and "--except a,b" as (a b).
(define (except names)
  (cond ((not names) '()) ((list? names) names) (else (list names))))

;; The page of the live view, its script and style.
(define web (string-append bin "/../web"))

;; The view is loaded only by the commands that serve it: its HTTP server
;; costs a second to load.
(define (view-procedure name)
  (eval name (environment '(murdoch view))))

;; A port number given as an argument.
(define (port-argument c text)
  (let ((n (string->number text)))
    (if (and (exact-integer? n) (< 0 n 65536))
        n
        (mistake c (string-append "not a port number: " text)))))

(define (run-lab* cfg lab-file)
  (let ((option (lambda (name) (conf-get cfg (list 'command 'lab name)))))
    ;; bin/murdoch-lab starts the view, on this port (0: the lab's
    ;; port-base + 148), when MURDOCH_VIEW is set: by this, and only this.
    (if (option 'view)
        (setenv "MURDOCH_VIEW" (number->string (option 'view)))
        (unsetenv "MURDOCH_VIEW"))
    (run-lab bin lab-file (except (option 'except)) (option 'logs) (option 'trace)
             (let ((speed (option 'speed)))
               (and speed (number->string speed)))
             ;; A fork of the lab's loader becomes address space uid as
             ;; `murdoch aspace LAB UID` would: its ERROR line says so.
             (lambda (uid) (run (command-named "aspace") (list lab-file uid))))))

;; name, arguments (those in parentheses may be left out), what it does, its
;; options as (chibi app) writes them, and what runs it: a procedure of
;; the config and the arguments.
(define commands
  `((aspace (LAB NAME) "start address space NAME of the lab, until killed" ()
            ,(lambda (cfg lab name) (run-aspace lab (string->symbol name))))
    (repl (LAB (NAME)) "join the lab with a REPL, as NAME or as a guest" ()
          ,(lambda (cfg lab . name)
             (run-repl lab (and (pair? name) (string->symbol (car name))))))
    (lab (LAB) "start the simulator and every address space of the lab, until stopped \
                (Ctrl-C); an address space that dies is started again, at most three \
                times a minute"
         ((trace string "write the simulator's animated SVG trace here")
          (speed real "simulated seconds per wall second")
          (logs string "the children's logs go in this folder (default: a fresh one, \
                        named when the lab starts)")
          (except (list symbol) "start all but these address spaces (a,b,...), to join \
                                 by hand")
          (view integer "also serve the live view in the browser, at \
                         http://127.0.0.1:PORT/ (PORT may be left out: the lab's \
                         port-base + 148)"))
         ,(lambda (cfg lab) (run-lab* cfg lab)))
    (pose (LAB FILE) "pose the task FILE evaluates to, as a guest of the running lab"
          ((detach boolean "hand the task to the lab, print its id and exit at once: \
                            the lab keeps it, on a coordinator and a standby it chooses"))
          ,(lambda (cfg lab file) (run-pose lab file (conf-get cfg '(command pose detach)))))
    (tasks (LAB) "list the tasks handed to the lab (pose --detach): each one's state, \
                  coordinator and standby" ()
           ,(lambda (cfg lab) (run-tasks lab)))
    (wait (LAB ID) "wait for the task ID handed to the lab, and print its results" ()
          ,(lambda (cfg lab id) (run-wait lab (string->symbol id))))
    (cancel (LAB ID) "cancel the task ID handed to the lab" ()
            ,(lambda (cfg lab id) (run-cancel lab (string->symbol id))))
    (demo (LAB) "start the lab, pose the dual-sonar task, show where the trace is" ()
          ,(lambda (cfg lab) (run-demo bin lab)))
    (view (LAB (PORT)) "show the running lab in the browser: serve its live view at \
                        http://127.0.0.1:PORT/ (default: the lab's port-base + 148), \
                        writing its trace as it goes"
          ((trace string "write the view's trace here (default: runs/LAB-SECONDS.jsonl)"))
          ,(lambda (cfg lab . port)
             ((view-procedure 'run-view)
              web lab (and (pair? port) (port-argument (command-named "view") (car port)))
              (conf-get cfg '(command view trace)))))
    (replay (TRACE (PORT)) "serve the view of a finished run from its trace, to play in \
                            the browser (default port 7248)" ()
            ,(lambda (cfg trace . port)
               ((view-procedure 'run-replay)
                web trace
                (and (pair? port) (port-argument (command-named "replay") (car port))))))
    (check (LAB) "check the lab file for mistakes, and start nothing" ()
           ,(lambda (cfg lab) (run-check lab)))
    (status (LAB) "show each address space of the running lab: up since, pose, battery, \
                   the subjects held and by whom" ()
            ,(lambda (cfg lab) (run-status lab)))
    (help ((COMMAND)) "show this help, or a command's" ()
          ,(lambda (cfg . name) (show-help name)))))

(define (command-named name) (assq (string->symbol name) commands))
(define (command-args c) (cadr c))
(define (command-doc c) (car (cddr c)))
(define (command-options c) (cadr (cddr c)))
(define (command-proc c) (car (cddr (cddr c))))

;; An option of a command, (NAME TYPE DOC), by name.
(define (option-key o) (car o))
(define (option-type o) (cadr o))
(define (option-doc o) (car (cddr o)))

(define (optional? arg) (pair? arg))
(define (arg-name arg) (symbol->string (if (pair? arg) (car arg) arg)))

(define (usage-line c)
  (string-append
   "murdoch " (symbol->string (car c))
   (if (null? (command-options c)) "" " [OPTION ...]")
   (apply string-append
          (map (lambda (a)
                 (if (optional? a)
                     (string-append " [" (arg-name a) "]")
                     (string-append " " (arg-name a))))
               (command-args c)))))

(define (show-usage out)
  (write-string "Murdoch: task allocation for teams of robots.\n\nUsage:\n" out)
  (for-each (lambda (c)
              (write-string (string-append "  " (usage-line c) "\n      "
                                           (command-doc c) "\n")
                            out))
            commands)
  (write-string "\n  murdoch --help, murdoch help COMMAND, murdoch COMMAND --help, \
                 murdoch --version\n"
                out))

(define (show-command-usage c out)
  (write-string (string-append "Usage: " (usage-line c) "\n  " (command-doc c) "\n") out)
  (for-each (lambda (o)
              (write-string (string-append "  --" (symbol->string (option-key o))
                                           (string-upcase-name (option-type o))
                                           "\n      " (option-doc o) "\n")
                            out))
            (command-options c)))

(define (string-upcase-name type)
  (cond ((pair? type) " A,B,...") ((eq? type 'real) " X") ((eq? type 'integer) " PORT")
        ((eq? type 'boolean) "")
        (else " TEXT")))

(define (show-help name)
  (cond ((null? name) (show-usage (current-output-port)))
        ((command-named (car name))
         => (lambda (c) (show-command-usage c (current-output-port))))
        (else (mistake #f (string-append "no command " (car name)
                                         (nearest (car name)))))))

(define (nearest name)
  (let ((near (find-nearest-edits name (map (lambda (c) (symbol->string (car c)))
                                            commands))))
    (if (and (pair? near) (<= (edit-distance name (car near)) 2))
        (string-append "; did you mean " (car near) "?")
        "")))

;; One line saying what is wrong, the usage, and exit 2.
(define (mistake c what)
  (let ((err (current-error-port)))
    (write-string (string-append "murdoch"
                                 (if c (string-append " " (symbol->string (car c))) "")
                                 ": " what "\n\n")
                  err)
    (if c (show-command-usage c err) (show-usage err))
    (exit 2)))

;; Whether the positional arguments suit the command c.
(define (check-arity c args)
  (let ((required (count (lambda (a) (not (optional? a))) (command-args c)))
        (most (length (command-args c))))
    (cond ((< (length args) required)
           (mistake c (string-append "missing " (arg-name (list-ref (command-args c)
                                                                     (length args))))))
          ((> (length args) most)
           (mistake c (string-append "too many arguments: " (last args)))))))

(define (help-flag? arg) (member arg '("--help" "-h")))

(define (option-word? arg)
  (and (> (string-length arg) 2) (string=? "--" (substring arg 0 2))))

;; "--speed=2" names speed, as "--speed" does.
(define (option-name arg)
  (let ((end (or (string-index arg #\=) (string-length arg))))
    (string->symbol (substring arg 2 end))))

(define (inline-value arg)
  (let ((i (string-index arg #\=)))
    (and i (substring arg (+ i 1) (string-length arg)))))

(define (string-index s ch)
  (let loop ((i 0))
    (cond ((= i (string-length s)) #f)
          ((char=? (string-ref s i) ch) i)
          (else (loop (+ i 1))))))

;; Each option of c on the command line args, and its value, checked
;; before (chibi app) reads them: it would call a bad number an unknown
;; option, and take an unknown option's value for an argument.  --view's
;; port may be left out, so a word after it that is no number is an
;; argument, unless that leaves one too many.
(define (check-options c args)
  (let loop ((rest args))
    (when (pair? rest)
      (let ((arg (car rest)))
        (cond
         ((not (option-word? arg)) (loop (cdr rest)))
         ((assq (option-name arg) (command-options c))
          => (lambda (o)
               (let ((value (or (inline-value arg)
                                (and (pair? (cdr rest)) (cadr rest))))
                     (next (if (inline-value arg) (cdr rest) (cddr* rest))))
                 (cond
                  ((eq? (option-type o) 'boolean)
                   (if (inline-value arg) (mistake c (value-mistake o (inline-value arg))))
                   (loop (cdr rest)))
                  ((and (eq? (option-key o) 'view) (not (inline-value arg))
                        (not (and value (string->number value))))
                   (if (and value (not (option-word? value))
                            (> (length (positional args)) (length (command-args c))))
                       (mistake c (value-mistake o value)))
                   (loop (cdr rest)))
                  ((not (and value (value-fits? (option-type o) value)))
                   (mistake c (value-mistake o value)))
                  (else (loop next))))))
         (else
          (mistake c (string-append "unknown option " arg (nearest-option c arg)))))))))

(define (cddr* ls) (if (pair? (cdr ls)) (cddr ls) '()))

(define (value-fits? type text)
  (let ((n (string->number text)))
    (case type
      ((real) (and (real? n) (positive? n)))
      ((integer) (and (exact-integer? n) (< 0 n 65536)))
      (else (not (option-word? text))))))

(define (value-mistake o value)
  (string-append "--" (symbol->string (option-key o)) " takes "
                 (case (option-type o)
                   ((real) "a positive number")
                   ((integer) (if (eq? (option-key o) 'view) "a port number, or nothing"
                                  "a port number"))
                   ((string) "a name")
                   ((boolean) "no value")
                   (else "names, as a,b,..."))
                 (if value (string-append ", not " value) "")))

(define (nearest-option c arg)
  (let* ((names (map (lambda (o) (string-append "--" (symbol->string (option-key o))))
                     (command-options c)))
         (near (find-nearest-edits arg names)))
    ;; Two edits from a name of another first letter is another word.
    (if (and (pair? near)
             (let ((d (edit-distance arg (car near))))
               (or (<= d 1)
                   (and (= d 2) (> (string-length arg) 2)
                        (char=? (string-ref arg 2) (string-ref (car near) 2))))))
        (string-append "; did you mean " (car near) "?")
        "")))

;; (chibi app) wants a command's options before its arguments; people
;; write `murdoch lab LAB --trace FILE` too.  Every option takes a value
;; but --view, whose port may be left out (it is then 0), and a flag.
(define (options-first args)
  (let loop ((rest args) (options '()) (positional '()))
    (cond
     ((null? rest) (append (reverse options) (reverse positional)))
     ((and (equal? (car rest) "--view")
           (or (null? (cdr rest)) (not (string->number (cadr rest)))))
      (loop (cdr rest) (cons* "0" "--view" options) positional))
     ((flag-word? (car rest))
      (loop (cdr rest) (cons (car rest) options) positional))
     ((option-word? (car rest))
      (if (or (null? (cdr rest)) (inline-value (car rest)))
          (loop (cdr rest) (cons (car rest) options) positional)
          (loop (cddr rest) (cons* (cadr rest) (car rest) options) positional)))
     (else (loop (cdr rest) options (cons (car rest) positional))))))

;; Whether arg is a flag, an option of no value: --detach.
(define (flag-word? arg)
  (any (lambda (c)
         (any (lambda (o) (and (eq? (option-type o) 'boolean)
                               (equal? arg (string-append "--" (symbol->string
                                                                (option-key o))))))
              (command-options c)))
       commands))

(define (positional args)
  (let loop ((rest args) (acc '()))
    (cond ((null? rest) (reverse acc))
          ((and (equal? (car rest) "--view")
                (or (null? (cdr rest)) (not (string->number (cadr rest)))))
           (loop (cdr rest) acc))
          ((flag-word? (car rest)) (loop (cdr rest) acc))
          ((option-word? (car rest))
           (loop (if (and (pair? (cdr rest)) (not (inline-value (car rest))))
                     (cddr rest)
                     (cdr rest))
                 acc))
          (else (loop (cdr rest) (cons (car rest) acc))))))

(define (app-spec c started!)
  `(murdoch "Murdoch"
    (,(car c) ,(command-doc c) (@ ,@(command-options c))
     (,(lambda (cfg spec . args)
         (started!)
         (apply (command-proc c) cfg args))))))

;; Runs command c.  An option (chibi app) does not know is a mistake on
;; the command line; an error once the command runs (a lab file's
;; mistake, a port in use) is one ERROR line, which bin/murdoch-lab shows
;; of a child that dies; either exits 2.
(define (run c args)
  (check-options c args)
  (check-arity c (positional args))
  (let ((started? #f))
    (guard (e ((and (error-object? e) started?)
               (write-string (string-append "murdoch " (symbol->string (car c))
                                            ": ERROR: " (error-message-naming e) "\n")
                             (current-error-port))
               (exit 2))
              ((error-object? e) (mistake c (error-message e))))
      (run-application (app-spec c (lambda () (set! started? #t)))
                       (cons* "murdoch" (symbol->string (car c)) (options-first args))))))

(define (main args)
  (cond
   ((null? args) (mistake #f "no command given"))
   ((help-flag? (car args)) (show-usage (current-output-port)))
   ((equal? (car args) "--version")
    (write-string (string-append "murdoch " version "\n")))
   ((command-named (car args))
    => (lambda (c)
         (if (find help-flag? (cdr args))
             (show-command-usage c (current-output-port))
             (run c (cdr args)))))
   (else (mistake #f (string-append "no command " (car args) (nearest (car args)))))))

(main (cdr (command-line)))
