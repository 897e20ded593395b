;;; No run spins (docs/box-move.md): a box whose rear face stands 200 mm
;;; from a wall leaves the pushers no place behind it.  The pushers stop
;;; after 60 s of their own clock without coming nearer, the task fails
;;; saying which step and what held it, and the demo ends on its own,
;;; judged, long before tests/run's limit (a run that spun would be killed
;;; there, with no judge's line).
;;; tests/run lane: box
(import (scheme base) (scheme write) (scheme read) (scheme file) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")   ; tests/run runs from the top

(define dir (temporary-directory))

(define (write-file name text)
  (call-with-output-file (string-append dir "/" name)
    (lambda (out) (display text out))))

(write-file "path.scm" "(define box-path '((-3500 0) (-1500 0) (0 1000)))\n(define box-side 600)\n")
(write-file "lab.scm"
  (string-append
   "(lab box-against-a-wall (port-base 7300) (key-file \"box.key\")\n"
   "  (code \"path.scm\" \"" (tool-path "examples/box-move.scm") "\")\n"
   "  (aspace ada (robot (pose -2000 1200 0)) (capabilities mobile fiducial))\n"
   "  (aspace bram (robot (pose -2000 -1200 0)) (capabilities mobile fiducial))\n"
   "  (aspace cato (robot (pose 0 -2000 90)) (capabilities mobile fiducial))\n"
   "  (world (wall -4000 -3000 4000 -3000) (wall 4000 -3000 4000 3000)\n"
   "         (wall 4000 3000 -4000 3000) (wall -4000 3000 -4000 -3000)\n"
   "         (box -3500 0 600 600 0))\n"
   "  (simulator (speed 2)))\n"))

(test-begin "box move, no place behind the box: the task stops and says why")
(let* ((run (run-demo (string-append dir "/lab.scm") "")) (text (cdr run)))
  (test "the demo says the task did not complete" #f (car run))
  (test-assert "step 1 failed, a pusher saying what held it"
    (text-contains? text "take-place: no nearer its place behind the box in 60 s: "))
  (test-assert "the task failed"
    (text-contains? text ": failed"))
  (test-assert "the run ended on its own and was judged"
    (text-contains? text "box-move: the box ended at"))
  (if (not (text-contains? text "take-place: no nearer")) (show-failed-run text)))
(delete-file-hierarchy dir)
(test-end)
(test-exit)
