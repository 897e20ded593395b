;;; The task `make demo-box` poses: a team moves the box along its path,
;;; as box-move.scm, the lab's code file, defines it.  By hand:
;;;   bin/murdoch pose examples/box-lab.scm examples/pose-box-move.scm
(box-move-task)
