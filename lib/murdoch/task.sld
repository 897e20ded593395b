;;> The task life cycle: start-task answers a task record at once;
;;> task-status, task-wait, cancel-task and tasks read and act on it; the
;;> components are watched by heartbeats, and a lost robot's restartable
;;> component is given to another.  See lib/murdoch/task.scm's header.

(define-library (murdoch task)
  (export start-task task? task-id task-name task-status task-wait cancel-task
          tasks task-step start-steps pose-steps
          waiting-ranks waiting-for receive-offer receive-give-way note-waiters!)
  (import (scheme base) (scheme char) (scheme cxr) (scheme time)
          (srfi 1) (srfi 18) (srfi 132)
          (only (chibi ast) thread-interrupt!)
          (murdoch scheduler) (murdoch log) (murdoch wait) (murdoch abandon)
          (murdoch remote-error) (murdoch sendable) (murdoch lab)
          (murdoch remote) (murdoch progress)
          (murdoch team) (murdoch pose-task) (murdoch component)
          (only (murdoch pubsub) subscribe unsubscribe publish request capability-layout
                subscription-statuses on-free! offer-subjects!)
          (only (murdoch takers) explain-components))
  (include "task.scm"))
