;;> Assignment: components to distinct robots at least total cost, by the
;;> Hungarian method (docs/allocation.md).

(define-library (murdoch task assign)
  (export assign-optimal assign-greedy assignment-cost dominant-cost)
  (import (scheme base) (scheme inexact))
  (include "assign.scm"))
