;;; The box team on the layout of seed 38 with its fault (the pusher and the time its seed draws),
;;; drawn by tools/box-layout.scm: a layout no example has, which the
;;; team knows only by what its robots sense and the path the user gives.
;;; Its fault is the kind that failed most: a 410 mm box, narrower than two
;;; robots, whose outside pusher is lost before a bend to the inside, so that
;;; the lost one's body lies against the lone pusher and holds the spare's
;;; place (docs/box-move.md).
;;; One case a file: tests/run gives each file 300 s.  tests/box-move-cases.scm.
;;; tests/run lane: box
(import (scheme base) (scheme write) (scheme read) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (only (chibi filesystem) delete-file-hierarchy)
        (murdoch testing harness))
(include "tests/box-move-cases.scm")   ; tests/run runs from the top
(test-begin "box move, generated layout 38, its outside pusher lost")
(generated-box-case 38 #t)
(test-end)
(test-exit)
