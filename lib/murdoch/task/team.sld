;;> MOVER's dynamic teams (thesis §3.3.3): with-team, on-list and what
;;> they run a team's procedures with.

(define-library (murdoch task team)
  (export open-teams! with-team on-list current-team with-team-proc-maker exec-on
          task-timeout t sort-list make-maxrandom
          with-coordinator team-barrier team-send! team-receive step-team
          make-coordinator release-coordinator! team-answer team-held?)
  (import (scheme base) (srfi 1) (srfi 18) (srfi 27) (srfi 132)
          (only (chibi ast) thread-interrupt!) (murdoch sys) (murdoch code)
          (only (murdoch wire) error-message)
          (only (murdoch lab) lab-default setting *node* this-node node-teams
                node-teams-set!)
          (murdoch remote) (only (murdoch pubsub) request) (murdoch task progress)
          (murdoch task metric))
  (include "team.scm"))
