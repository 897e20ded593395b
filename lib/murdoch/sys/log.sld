;;> One-line log messages on standard error, an error's text in one line,
;;> and the clock a person reads.

(define-library (murdoch sys log)
  (export utc-seconds set-log-name! stamp-log-lines! log-note log-warn
          condition-message)
  (import (scheme base) (scheme write) (srfi 18)
          (only (chibi) call-with-output-string strip-syntactic-closures)
          (only (murdoch sys scheduler) stack-guard-tripped?)
          (only (chibi time) get-time-of-day timeval-seconds timeval-microseconds))
  (include "log.scm"))
