;;> The robot's side of the task life cycle: run-component runs a started
;;> task's component here and stops it when its poser falls silent;
;;> component-heartbeat! and stop-component! are what the poser calls, and
;;> (orphan-periods) and (lost-periods) the lab's silent heartbeat periods
;;> before a component stops and a poser declares its robot lost
;;> (running.scm says why).  run-posed-component
;;> runs a component of pose-task's; components-running and
;;> components-ended list them all, for the status and the live view.

(define-library (murdoch task running)
  (export open-runs! run-component run-posed-component component-heartbeat! stop-component!
          await-component
          components-running components-ended ended-id ended-index ended-started
          ended-ended ended-end orphan-periods lost-periods)
  (import (scheme base) (srfi 1) (srfi 18) (murdoch sys) (murdoch code) (murdoch wire)
          (murdoch robot)
          (only (murdoch lab) setting *node* this-node node-runs node-runs-set!)
          (only (murdoch remote) hand-over-connection! release-call!))
  (include "running.scm"))
