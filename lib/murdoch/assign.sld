(define-library (murdoch assign)
  (export assign-optimal assign-greedy assignment-cost)
  (import (scheme base) (scheme inexact))
  (include "assign.scm"))
