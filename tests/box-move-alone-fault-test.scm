;;; The box team with no spare (examples/box-lab-alone.scm): the inside
;;; pusher killed midway, the other finishes alone and the task says that
;;; the lost pusher's part failed.
;;; One case a file: tests/run gives each file 300 s.  tests/box-move-cases.scm.
;;; tests/run lane: box
(import (scheme base) (scheme write) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")   ; tests/run runs from the top
(test-begin "box move, the inside pusher lost and no spare")
(box-case "examples/box-lab-alone.scm" "inside" #f)
(test-end)
(test-exit)
