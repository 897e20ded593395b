;;; The box team on the example lab: no fault, then the inside pusher
;;; killed midway (make demo-box FAULT=1).  tests/box-move-cases.scm.
(include "box-move-cases.scm")
(test-begin "box move")
(box-case "examples/box-lab.scm" "")
(box-case "examples/box-lab.scm" "inside")
(test-end)
(test-exit)
