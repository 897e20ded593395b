;;> One-line log messages on standard error, and the clock a person reads.

(define-library (murdoch sys log)
  (export utc-seconds set-log-name! stamp-log-lines! log-note log-warn)
  (import (scheme base) (scheme write)
          (only (chibi time) get-time-of-day timeval-seconds timeval-microseconds))
  (include "log.scm"))
