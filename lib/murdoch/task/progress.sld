;;> pose-task-progress: the port on which pose-task, its metrics and its
;;> team tell what they are doing.

(define-library (murdoch task progress)
  (export pose-task-progress progress)
  (import (scheme base) (scheme write) (only (chibi) call-with-output-string)
          (murdoch code))
  (include "progress.scm"))
