;;> bin/murdoch's commands: start an address space, join a lab at a REPL.

(define-library (murdoch cli command)
  (export join-lab run-aspace run-repl tell-who-is-away make-lab-environment
          make-repl-environment)
  (import (only (murdoch wire) error-message)
          (scheme base) (scheme read) (scheme write) (scheme eval) (scheme file)
          (scheme process-context) (srfi 1) (srfi 18)
          (only (chibi process) current-process-id set-signal-action! signal/pipe)
          (only (chibi filesystem) is-a-tty? open open/read open/non-block
                open-input-file-descriptor)
          (only (srfi 151) bitwise-ior) (murdoch sys) (murdoch code) (murdoch cli hints)
          (murdoch lab) (murdoch remote) (murdoch pubsub) (murdoch robot)
          (only (murdoch task) open-tasks! task-timeout pose-task-retries pose-task-backoff
                robot-freed! offer-on-joining!))
  (include "command.scm"))
