;;; The murdoch command: see `bin/murdoch help`.
(import (scheme base) (scheme process-context) (chibi app) (murdoch command))

(define (aspace cfg spec lab-file name)
  (run-aspace lab-file (string->symbol name)))

(define (repl* cfg spec lab-file . name)
  (run-repl lab-file (and (pair? name) (string->symbol (car name)))))

(run-application
 `(murdoch
   "Murdoch: task allocation for teams of robots"
   (or
    (aspace "start address space NAME of the lab" (@) (,aspace lab name))
    (repl "join the lab with a REPL, as NAME or as a guest" (@) (,repl* lab))
    (help "show this help" (,app-help-command))))
 (command-line))
