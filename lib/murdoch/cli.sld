;;> The command line: hints, the address-space and REPL commands, and
;;> the lab's launcher.

(define-library (murdoch cli)
  (export join-lab run-aspace run-repl tell-who-is-away make-repl-environment
          run-lab run-pose run-demo run-status run-check run-tasks run-wait run-cancel)
  (import (murdoch cli command) (murdoch cli hints) (murdoch cli launch)))
