;;> Threads for what nobody waits for: spawn, and the pool of workers a
;;> remote-run!'s procedure runs in.

(define-library (murdoch worker)
  (export spawn run-in-worker)
  (import (scheme base) (srfi 1) (srfi 18)
          (murdoch scheduler) (murdoch wait) (murdoch log)
          (murdoch remote-error) (murdoch sandbox))
  (include "worker.scm"))
