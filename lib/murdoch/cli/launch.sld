;;> The commands that run a whole lab: \scheme{lab} starts it, \scheme{pose}
;;> poses a task to it from a file, \scheme{demo} does both for the thesis's
;;> dual-sonar task.
(define-library (murdoch cli launch)
  (export lab-lines run-lab run-pose run-demo run-status run-check run-tasks run-wait
          run-cancel)
  (import (scheme base) (scheme read) (scheme write) (scheme eval) (scheme file)
          (scheme process-context) (srfi 1)
          (only (chibi process) execute current-process-id fork waitpid
                wait/no-hang set-signal-action! signal/interrupt signal/quit signal/kill
                signal/term)
          (only (chibi filesystem) open-pipe open open/read open/write open/append
                open/create duplicate-file-descriptor-to set-file-descriptor-flags!
                open-input-file-descriptor open-output-file-descriptor)
          (only (chibi string) string-prefix?) (only (chibi ast) gc)
          (only (srfi 27) random-source-pseudo-randomize! default-random-source)
          (only (scheme time) current-second)
          (only (srfi 151) bitwise-and bitwise-ior arithmetic-shift)
          (only (murdoch sys) set-process-name! die-with-parent!) (murdoch lab)
          (murdoch cli command) (only (murdoch cli hints) eval-with-hints)
          (only (murdoch remote) remote-timeout)
          (only (murdoch code) make-lab-environment check-lab-code at-form-line)
          (only (murdoch wire) error-message)
          (only (murdoch task) write-lab-status lab-task-line status-state step-status?
                step-status-entries lab-tasks task? start-task task-wait task-status
                cancel-task task-id task-state task-state-text))
  (include "launch.scm"))
