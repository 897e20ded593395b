;;; The murdoch command: see `bin/murdoch help`.
(import (scheme base) (scheme process-context) (srfi 1) (chibi app) (chibi config)
        (only (chibi pathname) path-directory)
        (murdoch command) (murdoch launch))

(define (aspace cfg spec lab-file name)
  (run-aspace lab-file (string->symbol name)))

(define (repl* cfg spec lab-file . name)
  (run-repl lab-file (and (pair? name) (string->symbol (car name)))))

;; The sh scripts that supervise processes live beside this file.
(define bin (path-directory (car (command-line))))

(define (lab cfg spec lab-file)
  (let ((option (lambda (name) (conf-get cfg (list 'command 'lab name)))))
    (run-lab bin lab-file (except (option 'except)) (option 'logs) (option 'trace)
             (let ((speed (option 'speed)))
               (and speed (number->string speed))))))

;; (chibi app) reads "--except a" as a and "--except a,b" as (a b).
(define (except names)
  (cond ((not names) '()) ((list? names) names) (else (list names))))

(define (pose cfg spec lab-file task-file)
  (run-pose lab-file task-file))

(define (demo cfg spec lab-file)
  (run-demo bin lab-file))

;; (chibi app) wants a command's options before its arguments; people
;; write `murdoch lab LAB --trace FILE` too.  Every option takes a value.
(define (options-first args)
  (if (< (length args) 2)
      args
      (let loop ((rest (cddr args)) (options '()) (positional '()))
        (cond
         ((null? rest)
          (cons* (car args) (cadr args)
                 (append (reverse options) (reverse positional))))
         ((and (> (string-length (car rest)) 2)
               (string=? "--" (substring (car rest) 0 2))
               (pair? (cdr rest)))
          (loop (cddr rest) (cons* (cadr rest) (car rest) options) positional))
         (else (loop (cdr rest) options (cons (car rest) positional)))))))

(run-application
 `(murdoch
   "Murdoch: task allocation for teams of robots"
   (or
    (aspace "start address space NAME of the lab" (@) (,aspace lab name))
    (repl "join the lab with a REPL, as NAME or as a guest" (@) (,repl* lab))
    (lab "start the simulator and every address space of the lab, until stopped"
         (@ (trace string "write the simulator's animated SVG trace here")
            (speed real "simulated seconds per wall second")
            (logs string "the children's logs go here (default: a fresh folder)")
            (except (list symbol) "start all but these address spaces (a,b,...)"))
         (,lab lab))
    (pose "pose the task FILE evaluates to, as a guest of the running lab"
          (@) (,pose lab file))
    (demo "start the lab, pose the dual-sonar task, show where the trace is"
          (@) (,demo lab))
    (help "show this help" (,app-help-command))))
 (options-first (command-line)))
