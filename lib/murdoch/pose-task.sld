(define-library (murdoch pose-task)
  (export pose-task negotiate pose-task-progress task-timeout
          location-metric-maker load-metric-maker load-metric reverse-metric
          metric-by metric-by-asking reckon-distance-between sort-response resolve-conflicts
          with-team-proc-maker with-team on-list current-team exec-on t
          sort-list make-maxrandom)
  (import (scheme base) (scheme write) (scheme inexact) (scheme cxr)
          (srfi 1) (srfi 18) (srfi 27) (srfi 132)
          (only (chibi ast) procedure-code procedure-vars opcode? thread-interrupt!)
          (only (chibi) call-with-output-string)
          (murdoch log) (murdoch abandon) (murdoch sendable) (murdoch sandbox)
          (murdoch remote) (murdoch pubsub)
          (murdoch trip-client))
  (include "pose-task.scm"))
