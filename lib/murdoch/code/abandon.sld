;;> Abandoned calls: a thread whose caller gave up stops at its next robot
;;> command or remote call, or is woken in its wait for a robot's motion.
(define-library (murdoch code abandon)
  (export abandon-thread! forget-abandoned! abandoned? check-not-abandoned
          abandoned-error? despite-abandonment with-wake-on-abandon)
  (import (scheme base) (only (srfi 1) delete) (srfi 18) (only (murdoch sys) with-lock)
          (only (chibi) make-exception exception? exception-kind))
  (include "abandon.scm"))
