(define-library (murdoch command)
  (export join-lab run-aspace run-repl tell-who-is-away make-lab-environment
          make-repl-environment)
  (import (scheme base) (scheme read) (scheme eval) (scheme file)
          (scheme process-context)
          (srfi 1) (srfi 18)
          (only (chibi process) current-process-id)
          (only (chibi filesystem) is-a-tty? open open/read open/non-block
                open-input-file-descriptor)
          (only (srfi 151) bitwise-ior)
          (murdoch log)
          (murdoch sandbox) (murdoch guard) (murdoch lab) (murdoch remote) (murdoch pubsub)
          (murdoch trip-client))
  (include "command.scm"))
