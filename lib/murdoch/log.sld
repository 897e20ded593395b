(define-library (murdoch log)
  (export set-log-name! log-note log-warn)
  (import (scheme base) (scheme write))
  (include "log.scm"))
