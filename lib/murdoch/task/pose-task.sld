;;> pose-task: the negotiation that gives a task's components their
;;> robots, and runs them as a team.  Exports the metrics and teams of
;;> (murdoch task metric) and (murdoch task team) with it, as the thesis's
;;> new-task.scm had them.

(define-library (murdoch task pose-task)
  (export open-poses! pose-task negotiate negotiated-winners negotiated-types negotiated-name
          winner-uid winner-promise check-task pose-task-progress task-timeout
          pose-task-assignment pose-task-priority pose-task-retries
          pose-task-backoff pose-task-excluded pose-task-reservation pose-task-explain
          receive-rival pose-negotiations
          reservation-aspace-uid task-key task-key-parts lab-task-key lab-task-key?
          location-metric-maker load-metric-maker load-metric reverse-metric
          metric-by metric-by-asking metric-within compose-metrics
          reckon-distance-between sort-response resolve-conflicts
          with-team-proc-maker with-team on-list current-team exec-on t
          sort-list make-maxrandom)
  (import (only (murdoch wire) error-message)
          (scheme base) (scheme write) (scheme inexact) (scheme cxr) (scheme time)
          (srfi 1) (srfi 18) (srfi 27) (srfi 132)
          (only (chibi ast) procedure-code procedure-vars opcode? thread-interrupt!)
          (only (chibi) call-with-output-string)
          (only (chibi process) current-process-id) (murdoch sys) (murdoch code)
          (only (murdoch lab) lab-default *node* this-node node-poses node-poses-set!)
          (murdoch remote) (murdoch pubsub) (murdoch task assign)
          (murdoch task progress) (murdoch task metric) (murdoch task takers)
          (murdoch task team) (only (murdoch task running) run-posed-component))
  (include "pose-task.scm" "winners.scm" "rivals.scm"))
