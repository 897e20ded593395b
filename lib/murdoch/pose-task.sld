;;> pose-task: the negotiation that gives a task's components their
;;> robots, and runs them as a team.  Exports the metrics and teams of
;;> (murdoch metric) and (murdoch team) with it, as the thesis's
;;> new-task.scm had them.

(define-library (murdoch pose-task)
  (export pose-task negotiate check-task pose-task-progress task-timeout
          pose-task-assignment pose-task-priority pose-task-retries
          pose-task-backoff pose-task-excluded receive-rival pose-negotiations
          reservation-aspace-uid
          location-metric-maker load-metric-maker load-metric reverse-metric
          metric-by metric-by-asking metric-within compose-metrics
          reckon-distance-between sort-response resolve-conflicts
          with-team-proc-maker with-team on-list current-team exec-on t
          sort-list make-maxrandom)
  (import (scheme base) (scheme write) (scheme inexact) (scheme cxr)
          (scheme time)
          (srfi 1) (srfi 18) (srfi 27) (srfi 132)
          (only (chibi ast) procedure-code procedure-vars opcode? thread-interrupt!)
          (only (chibi) call-with-output-string)
          (only (chibi process) current-process-id)
          (murdoch log) (murdoch abandon) (murdoch sendable) (murdoch sandbox)
          (murdoch remote) (murdoch pubsub) (murdoch assign)
          (murdoch progress) (murdoch metric) (murdoch takers) (murdoch team))
  (include "pose-task.scm"))
