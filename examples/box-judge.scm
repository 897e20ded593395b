;;; tools/chibi examples/box-judge.scm B14-LOG [NAME]: where the box of
;;; box-lab.scm ended, as the simulator says when it stops ("b14: box 0
;;; ends at X Y HEADING after T s"), against box-path.scm's goal.  The
;;; simulator's word is the judge's alone: the robots only ever see the box
;;; through their fiducial finders.  Prints the verdict and two bench
;;; lines, NAME-goal-error-mm (NAME default box-move) and
;;; box-move-sim-seconds; exits 0 when the box arrived, 1 when it did not,
;;; 2 when the log has no such line.
(import (scheme base) (scheme write) (scheme read) (scheme file) (scheme inexact)
        (scheme process-context) (scheme eval) (srfi 1) (only (meta) mutable-environment))

(define (folder-of path)
  (let loop ((i (- (string-length path) 1)))
    (cond ((< i 0) "./")
          ((char=? #\/ (string-ref path i)) (substring path 0 (+ i 1)))
          (else (loop (- i 1))))))

;; box-path.scm, beside this file, read into an environment of its own:
;; the lab's code is written for the lab's environment, not as a library.
(define path-env
  (let ((env (mutable-environment '(scheme base) '(scheme inexact)))
        (file (string-append (folder-of (car (command-line))) "box-path.scm")))
    (call-with-input-file file
      (lambda (in)
        (let loop ()
          (let ((form (read in)))
            (unless (eof-object? form) (eval form env) (loop))))))
    env))

(define (from-path name) (eval name path-env))
(define (goal) ((from-path 'goal)))
(define (goal-heading) ((from-path 'goal-heading)))
(define (distance p q) ((from-path 'distance) p q))
(define (square-wrap a) ((from-path 'square-wrap) a))

;; (X Y HEADING SECONDS) from the simulator's line, or #f.
(define (box-end log)
  (call-with-input-file log
    (lambda (in)
      (let loop ((found #f))
        (let ((line (read-line in)))
          (cond ((eof-object? line) found)
                ((string-prefix? "b14: box 0 ends at " line)
                 (loop (let ((in (open-input-string (substring line 19 (string-length line)))))
                         (let* ((x (read in)) (y (read in)) (h (read in)))
                           (read in)
                           (list x y h (read in))))))
                (else (loop found))))))))

(define (string-prefix? p s)
  (and (>= (string-length s) (string-length p)) (string=? p (substring s 0 (string-length p)))))

(define (say . parts)
  (for-each display parts)
  (newline))

(define (judge log name)
  (let ((end (box-end log)))
    (if (not end)
        (begin (say "box-move: no \"b14: box 0 ends\" line in " log) (exit 2)))
    (let* ((err (distance end (goal)))
           (turn (abs (square-wrap (- (car (cddr end)) (goal-heading)))))
           (arrived? (and (<= err 300) (<= turn 20))))
      (say "box-move: the box ended at (" (exact (round (car end))) ", " (exact (round (cadr end)))
           ") heading " (car (cddr end)) " after " (cadr (cddr end)) " s; the goal is ("
           (car (goal)) ", " (cadr (goal)) ") heading " (exact (round (goal-heading))) ": "
           (exact (round err)) " mm and " (exact (round turn)) " degrees off, "
           (if arrived? "within" "outside") " 300 mm and 20 degrees")
      (say "bench: " name "-goal-error-mm " (exact (round err)) " mm")
      (say "bench: box-move-sim-seconds " (cadr (cddr end)) " s")
      (exit (if arrived? 0 1)))))

(let ((args (cdr (command-line))))
  (judge (car args) (if (pair? (cdr args)) (cadr args) "box-move")))
