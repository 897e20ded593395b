;;> Tasks: assignment, metrics, progress, takers, dynamic teams,
;;> pose-task and a task's life cycle.
;;> Its members are each a library of their own in task/.  It is a
;;> selection: the life cycle's members (record, rank, offers, holding,
;;> waiting) share their insides among themselves, which it leaves out.

(define-library (murdoch task)
  (export task-key task-key-parts assign-optimal assign-greedy assignment-cost
          dominant-cost run-component run-posed-component
          component-heartbeat! stop-component! components-running components-ended
          ended-id ended-index ended-started ended-ended ended-end
          lost-periods
          start-task task? task-id task-name task-state task-why task-state-text
          task-status task-wait cancel-task
          status-index status-state status-attempts
          step-status? step-status-index step-status-entries
          tasks listed-posed? listed-id listed-state listed-place listed-why
          listed-priority listed-held listed-wants listed-index listed-poser
          waiting-entries rank<? offer-on-joining!
          task-step start-steps pose-steps waiting-ranks waiting-for receive-offer
          receive-give-way note-waiters! location-metric-maker load-metric-maker
          load-metric reverse-metric metric-by metric-by-asking metric-within
          compose-metrics reckon-distance-between sort-response metric-keys measure-key?
          measured-response asking-procs sort-measured shuffle pose-task negotiate
          check-task pose-task-progress task-timeout pose-task-assignment
          pose-task-priority pose-task-retries pose-task-backoff pose-task-excluded pose-task-reservation
          receive-rival pose-negotiations reservation-aspace-uid resolve-conflicts
          with-team-proc-maker with-team on-list current-team exec-on t sort-list
          make-maxrandom progress explain-no-takers explain-components explanation?
          explanation-line explanation-free explanation-capable with-coordinator
          team-barrier team-send! team-receive step-team make-coordinator
          negotiated-winners negotiated-types negotiated-name winner-uid winner-promise)
  (import (murdoch task assign) (murdoch task running) (murdoch task metric)
          (murdoch task pose-task) (murdoch task progress) (murdoch task takers)
          (murdoch task team) (murdoch task record) (murdoch task rank)
          (murdoch task offers) (murdoch task holding) (murdoch task life-cycle)
          (murdoch task steps)))
