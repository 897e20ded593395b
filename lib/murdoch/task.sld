;;> Tasks: assignment, metrics, progress, takers, dynamic teams,
;;> pose-task, a task's life cycle, and tasks handed to the lab.
;;> Its members are each a library of their own in task/.

(define-library (murdoch task)
  (export task-key task-key-parts assign-optimal assign-greedy assignment-cost
          dominant-cost run-component run-posed-component
          component-heartbeat! stop-component! components-running components-ended
          ended-id ended-index ended-started ended-ended ended-end
          lost-periods
          start-task task? task-id task-name task-status task-wait cancel-task
          status-index status-state status-attempts
          step-status? step-status-index step-status-entries
          tasks listed-posed? listed-id listed-state listed-place listed-why
          listed-index listed-poser
          task-step start-steps pose-steps waiting-ranks waiting-for receive-offer
          receive-give-way note-waiters! location-metric-maker load-metric-maker
          load-metric reverse-metric metric-by metric-by-asking metric-within
          compose-metrics reckon-distance-between sort-response metric-keys measure-key?
          measured-response asking-procs sort-measured shuffle pose-task negotiate
          check-task pose-task-progress task-timeout pose-task-assignment
          pose-task-priority pose-task-retries pose-task-backoff pose-task-excluded
          receive-rival pose-negotiations reservation-aspace-uid resolve-conflicts
          with-team-proc-maker with-team on-list current-team exec-on t sort-list
          make-maxrandom progress explain-no-takers explain-components explanation?
          explanation-line explanation-free explanation-capable with-coordinator
          team-barrier team-send! team-receive step-team make-coordinator
          negotiated-winners negotiated-types negotiated-name winner-uid winner-promise
          await-component components-running lab-tasks lab-task-id lab-task-role
          lab-task-epoch lab-task-state lab-task-coordinator lab-task-standby
          lab-task-poser lab-task-took-over coordinate-task! coordinator-ping
          become-standby! receive-copy handed-role-of handed-entries handed-status
          handed-wait handed-cancel)
  (import (murdoch task assign) (murdoch task running)
          (except (murdoch task life-cycle) start-task start-steps task-status task-wait
                  cancel-task)
          (murdoch task detached)
          (murdoch task metric) (murdoch task pose-task) (murdoch task progress)
          (murdoch task takers) (murdoch task team)))
