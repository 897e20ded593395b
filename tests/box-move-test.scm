;;; A team moves a box (examples/box-move.scm, thesis §1.2): `make
;;; demo-box`'s run, in a fast-forward simulator (the lab's speed 2), on a
;;; port base of its own.  The box, which the robots see only through their
;;; fiducial finders, must end within 300 mm of the path's goal and 20
;;; degrees of its heading, as the simulator's own word at its exit says
;;; (examples/box-judge.scm).
(import (scheme base) (scheme write) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing))

(define dir (temporary-directory))
(define out (string-append dir "/demo.out"))

;; The demo's run from dir, so that the view's trace goes in dir/runs.
(define status
  (system? "sh" "-c"
           "cd \"$0\" && MURDOCH_PORT_BASE=$1 MURDOCH_DEMO_TASK=\"$2/examples/pose-box-move.scm\" MURDOCH_DEMO_JUDGE=\"$2/examples/box-judge.scm\" timeout -s KILL 400 \"$2/bin/murdoch\" demo \"$2/examples/box-lab.scm\" >\"$3\" 2>&1"
           dir (number->string (free-port-base dir)) (tool-path ".") out))

;; The number after "bench: NAME " in the demo's output, or #f.
(define (bench name)
  (let ((prefix (string-append "bench: " name " ")))
    (any (lambda (line)
           (and (>= (string-length line) (string-length prefix))
                (string=? prefix (substring line 0 (string-length prefix)))
                (read (open-input-string (substring line (string-length prefix)
                                                    (string-length line))))))
         (read-lines out))))

(test-begin "box move")
(test "the box arrives: within 300 mm of the goal and 20 degrees of its heading" #t
  (text-contains? (file-text out) "within 300 mm and 20 degrees"))
(test "the demo says so by its exit status" #t status)
(test-assert "its goal error, a bench line, is at most 300 mm"
  (let ((mm (bench "box-move-goal-error-mm"))) (and (real? mm) (<= mm 300))))
(test-assert "and its simulated seconds" (real? (bench "box-move-sim-seconds")))
(test-assert "both steps ran, the second to its end"
  (text-contains? (file-text out) ": step 2 done: ("))
(test-end)
(if (not status) (display (file-text out)))
(delete-file-hierarchy dir)
(test-exit)
