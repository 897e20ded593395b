;;> Tasks of several steps: task-step, start-steps and pose-steps; each
;;> step a task of start-task's, its components a team.

(define-library (murdoch task steps)
  (export task-step start-steps pose-steps step? step-parts resume-steps step-task-id
          team-keeper)
  (import (scheme base) (scheme cxr) (srfi 1) (srfi 18) (murdoch sys) (murdoch code)
          (murdoch remote) (murdoch task progress) (murdoch task team) (murdoch task record)
          (murdoch task rank) (murdoch task life-cycle))
  (include "steps.scm"))
