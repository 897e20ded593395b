;;> The task life cycle: start-task answers a task record at once;
;;> task-status, task-wait, cancel-task and tasks read and act on it; the
;;> components are watched by heartbeats, and a lost robot's restartable
;;> component is given to another.  See lib/murdoch/task/life-cycle.scm's header.

(define-library (murdoch task life-cycle)
  (export start-task task? task-id task-name task-status task-wait cancel-task
          status-index status-state status-attempts
          step-status? step-status-index step-status-entries
          tasks listed-posed? listed-id listed-state listed-place listed-why
          listed-index listed-poser task-step start-steps pose-steps
          waiting-ranks waiting-for receive-offer receive-give-way note-waiters!
          step? step-parts heartbeat-patience let-task-go! task-turn-copy adopt-task
          (rename task-state task-state-of))
  (import (scheme base) (scheme char) (scheme cxr) (srfi 1) (srfi 18)
          (srfi 132) (only (chibi ast) thread-interrupt!) (murdoch sys) (murdoch code)
          (murdoch wire) (murdoch lab) (murdoch remote) (murdoch task progress)
          (murdoch task team) (murdoch task pose-task) (murdoch task running)
          (only (murdoch pubsub) subscribe unsubscribe publish request
                capability-layout subscription-statuses on-free! offer-subjects!)
          (only (murdoch task takers) explain-components explanation-line
                explanation-free explanation-capable))
  (include "life-cycle.scm"))
