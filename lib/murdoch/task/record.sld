;;> The task record: a task started here, its components, the list of
;;> the tasks started here, and the readers of task-status's and
;;> (tasks)'s entries.

(define-library (murdoch task record)
  (export task? task-id task-name make-task task-components task-done
          task-state task-state-set! task-why task-why-set! task-team task-team-set! task-steps
          task-steps-set! task-turn task-turn-set! task-waiter task-waiter-set!
          task-acted task-acted-set!
          make-component component? component-index component-capabilities
          component-metric component-proc component-restartable? component-state
          component-state-set! component-attempts component-attempts-set!
          tasks-lock open-posed! posed-tasks add-posed! over? forget-over! fail-component!
          component-result check-task-record
          status-index status-state status-attempts
          step-status? step-status-index step-status-entries
          listed-posed? listed-id listed-state listed-place listed-why
          listed-priority listed-held listed-wants listed-index listed-poser)
  (import (scheme base) (scheme cxr) (srfi 1) (srfi 18)
          (only (murdoch lab) *node* this-node node-posed node-posed-set!))
  (include "record.scm"))
