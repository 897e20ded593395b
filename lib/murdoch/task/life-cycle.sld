;;> The task life cycle: start-task answers a task record at once;
;;> task-status, task-wait, cancel-task and tasks read and act on it; the
;;> components are watched by heartbeats, and a lost robot's restartable
;;> component is given to another.  See lib/murdoch/task/life-cycle.scm's header.

(define-library (murdoch task life-cycle)
  (export start-task task-status task-wait cancel-task tasks task-state-text
          new-task inheriting finish! task-of-args run-task supervise-all supervise
          after-attempt heartbeat-patience task-id-maker let-go?
          let-task-go!)
  (import (scheme base) (scheme cxr) (srfi 1) (srfi 18)
          (only (chibi ast) thread-interrupt!) (murdoch sys) (murdoch code)
          (murdoch wire) (murdoch lab) (murdoch remote) (murdoch task progress)
          (murdoch task pose-task) (murdoch task running) (murdoch task record)
          (murdoch task rank) (murdoch task holding) (murdoch task waiting))
  (include "life-cycle.scm"))
