;;> The library that user code imports: Murdoch's whole user interface, as
;;> the thesis names it.  It is also what received code can reach, so it
;;> exports nothing that touches files or processes.  Its lambda and define
;;> make closures that can travel; import it after (scheme base), or import
;;> (scheme base) without lambda and define.

(define-library (murdoch)
  (export (rename sendable-lambda lambda) (rename sendable-define define)
          aspace? aspace-uid local-aspace local-aspace-uid uid->aspace
          known-uids remote-run! remote-apply remote-timeout
          remote-error? remote-error-uid remote-error-message
          remote-timeout-error? remote-unreachable-error? remote-raised-error?
          remote-protocol-error?
          remote-apply-all remote-run-all! outcome-uid outcome-ok? outcome-value
          live-uids delivery-mode
          encap var-ref var-set! display-remote
          ;; publish/subscribe (lib/murdoch/pubsub/messaging.scm)
          subscribe unsubscribe subscriptions topic-status set-topic-status!
          subscribe-remote unsubscribe-remote
          publish request request-exclusive request-non-exclusive
          request-status subscription-statuses
          receive-publication receive-request receive-request-exclusive
          receive-request-non-exclusive receive-components
          get-system-load load-monitor battery-monitor
          battery-charging battery-low load-threshold
          set-battery-charging! set-battery-low! set-load-threshold!
          ;; pose-task, metrics and dynamic teams (lib/murdoch/task/pose-task.scm,
          ;; metric.scm, team.scm)
          pose-task negotiate pose-task-progress task-timeout
          pose-task-assignment pose-task-priority pose-task-retries
          pose-task-backoff pose-task-excluded receive-rival pose-negotiations
          location-metric-maker load-metric-maker load-metric reverse-metric
          metric-by metric-by-asking metric-within compose-metrics
          reckon-distance-between resolve-conflicts
          with-team-proc-maker with-team on-list current-team t
          sort-list make-maxrandom
          ;; the task life cycle (lib/murdoch/task/life-cycle.scm and its neighbours)
          start-task task? task-id task-name task-state task-why task-state-text
          task-status task-wait cancel-task
          status-index status-state status-attempts
          step-status? step-status-index step-status-entries
          tasks listed-posed? listed-id listed-state listed-place listed-why
          listed-priority listed-held listed-wants listed-index listed-poser run-component run-posed-component components-ended
          ended-id ended-index ended-started ended-ended ended-end
          component-heartbeat! stop-component!
          waiting-ranks waiting-entries waiting-for takers-here receive-offer receive-give-way note-waiters!
          task-step start-steps pose-steps with-coordinator team-barrier
          team-send! team-receive step-team team-answer team-held?
          ;; tasks handed to the lab (lib/murdoch/task/detached.scm)
          lab-tasks lab-task-id lab-task-role lab-task-epoch lab-task-state
          lab-task-coordinator lab-task-standby lab-task-poser lab-task-took-over
          await-component components-running coordinate-task! coordinator-ping
          become-standby! receive-copy receive-team-copy handed-role-of handed-entries handed-status
          handed-wait handed-cancel
                    ;; what the lab is doing (lib/murdoch/task/status.scm)
          aspace-report lab-status show-status aspace-started-at
          ;; the robot (lib/murdoch/robot/trip.scm)
          im goto-xy rotate translate angle-to-heading set-velocity stop-base
          reckon set-reckon-position! set-reckon-heading! robot-time
          sonar-start sonar-stop sonar-read ir-read bumpers-read skirt-read
          buttons-read lights say battery-voltage tethered? set-tether! fiducials
          fiducial-id fiducial-range fiducial-bearing fiducial-orientation
          safe-im safe-battery-voltage safe-reckon)
  (import (murdoch code) (murdoch remote) (murdoch pubsub) (murdoch task)
          (murdoch robot)))
