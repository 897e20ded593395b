;;> What the lab is doing, asked of every address space: the \scheme{status}
;;> command and REPL procedure.
(define-library (murdoch status)
  (export aspace-report lab-status show-status write-lab-status lab-line waiting-text
          report-uid report-since report-pose report-battery report-held report-tasks
          report-goal report-ended held-subject held-holder)
  (import (scheme base) (scheme write) (srfi 1) (srfi 132) (only (murdoch sys) utc-seconds)
          (murdoch lab) (murdoch remote) (murdoch pubsub) (murdoch robot) (murdoch task))
  (include "status.scm"))
