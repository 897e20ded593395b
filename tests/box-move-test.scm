;;; The box team on the example lab, without a fault (make demo-box).
;;; One case a file: tests/run gives each file 300 s.  tests/box-move-cases.scm.
;;; tests/run lane: box
(import (scheme base) (scheme write) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")   ; tests/run runs from the top
(test-begin "box move")
(box-case "examples/box-lab.scm" "")
(test-end)
(test-exit)
