;;> Threads for what nobody waits for: spawn, and the pool of workers a
;;> remote-run!'s procedure runs in.

(define-library (murdoch remote worker)
  (export spawn run-in-worker run-logged)
  (import (scheme base) (srfi 1) (srfi 18) (murdoch sys) (murdoch wire) (murdoch code))
  (include "worker.scm"))
