;;; The box team on a layout of its own (examples/box-lab-right.scm: the box
;;; elsewhere, twice as heavy, a path bending right), without a fault and
;;; with the inside pusher killed midway.  tests/box-move-cases.scm.
(include "box-move-cases.scm")
(test-begin "box move, bending right")
(box-case "examples/box-lab-right.scm" "")
(box-case "examples/box-lab-right.scm" "inside")
(test-end)
(test-exit)
