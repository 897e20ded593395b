;;; The box team on a layout of its own (box-lab-right.scm: the box
;;; elsewhere, twice as heavy, a path bending right), without a fault.
;;; One case a file: tests/run gives each file 300 s.  tests/box-move-cases.scm.
;;; tests/run lane: box
(import (scheme base) (scheme write) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")   ; tests/run runs from the top
(test-begin "box move, bending right")
(box-case "examples/box-lab-right.scm" "")
(test-end)
(test-exit)
