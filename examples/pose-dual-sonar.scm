;;; The task `bin/murdoch demo` poses: the thesis's dual-sonar task, which
;;; the lab's code file dual-sonar.scm defines.  Try it by hand with
;;;   bin/murdoch pose examples/tulane-lab.scm examples/pose-dual-sonar.scm
(dual-sonar-task)
