;;; The box team on the layout of seed 19 with its fault (the pusher and the time its seed draws),
;;; drawn by tools/box-layout.scm: a layout no example has, which the
;;; team knows only by what its robots sense and the path the user gives.
;;; One case a file: tests/run gives each file 300 s.  tests/box-move-cases.scm.
;;; tests/run lane: box
(import (scheme base) (scheme write) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")   ; tests/run runs from the top
(test-begin "box move, generated layout 19, a pusher lost")
(generated-box-case 19 #t)
(test-end)
(test-exit)
