;;> The command line: hints, the address-space and REPL commands, and
;;> the lab's launcher.
;;> Its members are each a library of their own in cli/.

(define-library (murdoch cli)
  (export join-lab run-aspace run-repl tell-who-is-away make-lab-environment
          make-repl-environment eval-with-hints lab-lines run-lab run-pose run-demo
          run-status run-check run-tasks run-wait run-cancel)
  (import (murdoch cli command) (murdoch cli hints) (murdoch cli launch)))
