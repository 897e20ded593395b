;;; box-lab-right.scm with its inside pusher killed midway.
;;; One case a file: tests/run gives each file 300 s.  tests/box-move-cases.scm.
;;; tests/run lane: box
(import (scheme base) (scheme write) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")   ; tests/run runs from the top
(test-begin "box move, bending right, the inside pusher lost")
(box-case "examples/box-lab-right.scm" "inside")
(test-end)
(test-exit)
