(define-library (murdoch task assign)
  (export assign-optimal assign-greedy assignment-cost dominant-cost)
  (import (scheme base) (scheme inexact))
  (include "assign.scm"))
