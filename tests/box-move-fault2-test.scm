;;; The box team on the example lab, the outside pusher killed midway (FAULT=2).
;;; One case a file: tests/run gives each file 300 s.  tests/box-move-cases.scm.
;;; tests/run lane: box
(import (scheme base) (scheme write) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")   ; tests/run runs from the top
(test-begin "box move, the outside pusher lost")
(box-case "examples/box-lab.scm" "outside")
(test-end)
(test-exit)
