;;> The commands that run a whole lab: \scheme{lab} starts it, \scheme{pose}
;;> poses a task to it from a file, \scheme{demo} does both for the thesis's
;;> dual-sonar task.
(define-library (murdoch cli launch)
  (export lab-lines run-lab run-pose run-demo run-status run-check)
  (import (scheme base) (scheme read) (scheme write) (scheme eval) (scheme file)
          (scheme process-context) (srfi 1)
          (only (chibi process) execute current-process-id) (murdoch lab)
          (murdoch cli command) (only (murdoch remote) remote-timeout)
          (only (murdoch code) make-lab-environment)
          (only (murdoch status) write-lab-status))
  (include "launch.scm"))
