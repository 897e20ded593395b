;;> MOVER's dynamic teams (thesis §3.3.3): with-team, on-list and what
;;> they run a team's procedures with.

(define-library (murdoch team)
  (export with-team on-list current-team with-team-proc-maker exec-on
          task-timeout t sort-list make-maxrandom
          with-coordinator team-barrier team-send! team-receive step-team make-coordinator)
  (import (scheme base) (srfi 1) (srfi 18) (srfi 27) (srfi 132)
          (only (chibi ast) thread-interrupt!)
          (murdoch scheduler) (murdoch wait) (murdoch log) (murdoch abandon) (murdoch sendable) (murdoch sandbox)
          (murdoch remote) (murdoch progress) (murdoch metric))
  (include "team.scm"))
