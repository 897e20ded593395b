;;> What the lab is doing, asked of every address space: the \scheme{status}
;;> command and REPL procedure.
(define-library (murdoch task status)
  (export aspace-report lab-status show-status write-lab-status lab-line waiting-text
          report-uid report-since report-pose report-battery report-held report-tasks
          report-goal report-ended report-handed held-subject held-holder lab-task-line
          lab-line waiting-text)
  (import (scheme base) (scheme write) (srfi 1) (srfi 132) (only (murdoch sys) utc-seconds)
          (murdoch lab) (murdoch remote) (murdoch pubsub) (murdoch robot)
          (only (murdoch task running) components-ended)
          (only (murdoch task life-cycle) tasks)
          (only (murdoch task rank) rank<? waiting-entries)
          (only (murdoch task detached) handed-entries lab-task-id lab-task-role
                lab-task-state lab-task-coordinator lab-task-standby lab-task-poser
                lab-task-took-over)
          (only (murdoch task record) listed-posed? listed-id listed-state
                listed-place listed-why listed-priority listed-held listed-wants
                listed-index listed-poser))
  (include "status.scm"))
