;;> Tasks: assignment, metrics, progress, takers, dynamic teams,
;;> pose-task, a task's life cycle, tasks handed to the lab, and the
;;> status of the lab.
;;> Its members are each a library of their own in task/; this umbrella
;;> exports what the families above use of them.

(define-library (murdoch task)
  (export open-tasks! task-key-parts run-component run-posed-component component-heartbeat!
          stop-component! components-ended ended-id ended-index ended-started
          ended-ended ended-end start-task task? task-id task-name task-status
          task-state task-why task-state-text task-wait cancel-task status-index
          status-state status-attempts
          step-status? step-status-index step-status-entries tasks listed-posed?
          listed-id listed-state listed-place listed-why listed-priority
          listed-held listed-wants listed-index listed-poser waiting-entries
          offer-on-joining! task-step start-steps pose-steps waiting-ranks
          waiting-for receive-offer receive-give-way note-waiters! robot-freed! takers-here
          location-metric-maker load-metric-maker load-metric reverse-metric
          metric-by metric-by-asking metric-within compose-metrics
          reckon-distance-between pose-task negotiate pose-task-progress
          task-timeout pose-task-assignment pose-task-priority pose-task-retries
          pose-task-backoff pose-task-excluded receive-rival pose-negotiations
          resolve-conflicts with-team-proc-maker with-team on-list current-team
          t sort-list make-maxrandom with-coordinator team-barrier team-send!
          team-receive step-team team-answer team-held? aspace-report lab-status show-status
          write-lab-status lab-line waiting-text report-since report-pose report-battery
          report-held report-tasks report-goal report-ended held-subject held-holder
          report-handed lab-task-line await-component components-running lab-tasks
          lab-task-id lab-task-role lab-task-epoch lab-task-state
          lab-task-coordinator lab-task-standby lab-task-poser lab-task-took-over
          coordinate-task! coordinator-ping become-standby! receive-copy receive-team-copy
          handed-role-of handed-entries handed-status handed-wait handed-cancel)
  (import (murdoch task assign) (murdoch task running) (murdoch task metric)
          (murdoch task pose-task) (murdoch task progress) (murdoch task takers)
          (murdoch task team) (murdoch task record) (murdoch task rank)
          (murdoch task offers) (murdoch task holding)
          (except (murdoch task life-cycle) start-task task-status task-wait cancel-task)
          (except (murdoch task steps) start-steps)
          (murdoch task detached) (murdoch task status) (murdoch task parts)))
