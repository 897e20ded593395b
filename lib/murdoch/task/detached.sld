;;> Tasks handed to the lab: start-task and start-steps with 'detach #t;
;;> the coordinator the lab chooses, and its standby, which takes over
;;> when it is lost; task-status, task-wait and cancel-task by id from
;;> anywhere, and lab-tasks.  See lib/murdoch/task/detached.scm's header.

(define-library (murdoch task detached)
  (export open-handing! start-task start-steps task-status task-wait cancel-task lab-tasks
          lab-task-id lab-task-role lab-task-epoch lab-task-state lab-task-coordinator
          lab-task-standby lab-task-poser lab-task-took-over
          coordinate-task! coordinator-ping become-standby! receive-copy
          receive-team-copy handed-role-of
          handed-entries handed-status handed-wait handed-cancel)
  (import (scheme base) (scheme cxr) (scheme write) (srfi 1) (srfi 18) (srfi 132)
          (only (chibi string) string-contains)
          (murdoch sys) (murdoch code) (murdoch wire) (murdoch lab) (murdoch remote)
          (murdoch task progress) (only (murdoch task pose-task) lab-task-key)
          (only (murdoch task running) components-running components-ended ended-id
                ended-index orphan-periods lost-periods)
          (murdoch task record)
          (only (murdoch task rank) make-turn turn-wait? turn-hold? turn-priority
                turn-deadline turn-posed)
          (rename (murdoch task life-cycle)
                  (start-task start-here) (task-status status-here)
                  (task-wait wait-here) (cancel-task cancel-here))
          (rename (only (murdoch task steps) start-steps step? step-parts task-step
                        resume-steps step-task-id team-keeper)
                  (start-steps start-steps-here))
          (only (murdoch pubsub) subscribe unsubscribe request get-system-load))
  (include "detached.scm" "standby.scm" "lab-tasks.scm"))
