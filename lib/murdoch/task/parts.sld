;;> The task layer's parts of the node: open-tasks! makes them as the
;;> node starts.
(define-library (murdoch task parts)
  (export open-tasks!)
  (import (scheme base) (murdoch task team) (murdoch task pose-task)
          (murdoch task running) (murdoch task record) (murdoch task rank)
          (murdoch task offers) (murdoch task waiting) (murdoch task detached))
  (include "parts.scm"))
