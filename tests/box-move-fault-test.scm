;;; The box team on the example lab with the other pusher killed midway
;;; (make demo-box FAULT=2).  tests/box-move-cases.scm.
(include "box-move-cases.scm")
(test-begin "box move, the outside pusher lost")
(box-case "examples/box-lab.scm" "outside")
(test-end)
(test-exit)
