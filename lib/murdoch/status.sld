;;> What the lab is doing, asked of every address space: the \scheme{status}
;;> command and REPL procedure.
(define-library (murdoch status)
  (export aspace-report lab-status show-status write-lab-status
          report-uid report-since report-pose report-battery report-held report-tasks
          report-goal report-ended report-handed held-subject held-holder lab-task-line)
  (import (scheme base) (scheme write) (srfi 1) (only (murdoch sys) utc-seconds)
          (murdoch lab) (murdoch remote) (murdoch pubsub) (murdoch robot) (murdoch task))
  (include "status.scm"))
