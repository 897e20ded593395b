;;> Why a task found not enough takers: for each component, who in the
;;> lab is capable of it and what each was doing.

(define-library (murdoch task takers)
  (export explain-no-takers explain-components takers-here explanation? explanation-lines
          explanation-line
          explanation-free explanation-capable)
  (import (scheme base) (scheme write) (srfi 1) (only (chibi) call-with-output-string)
          (murdoch lab) (murdoch code) (murdoch remote) (murdoch pubsub))
  (include "takers.scm"))
