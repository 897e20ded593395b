;;; The box team on the layout of seed 1 (a box in the south-east, a path of three legs bending left twice),
;;; drawn by tools/box-layout.scm: a layout no example has, which the
;;; team knows only by what its robots sense and the path the user gives.
;;; One case a file: tests/run gives each file 300 s.  tests/box-move-cases.scm.
;;; tests/run lane: box
(import (scheme base) (scheme write) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")   ; tests/run runs from the top
(test-begin "box move, generated layout 1")
(generated-box-case 1 #f)
(test-end)
(test-exit)
