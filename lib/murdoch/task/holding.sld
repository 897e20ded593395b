;;> Holding and giving way: a task started with hold #t keeps the robots
;;> it has won while it waits, and gives way on them to a better-ranked
;;> waiting task (docs/allocation.md has the argument).

(define-library (murdoch task holding)
  (export free-winner! hold-try let-go-held! keep-held! give-way!
          receive-give-way ask-way! unblock!
          blocked-on-itself?)
  (import (scheme base) (scheme cxr) (srfi 1) (srfi 18) (srfi 132)
          (murdoch sys) (murdoch lab) (murdoch remote) (murdoch task progress)
          (murdoch task pose-task) (murdoch task record) (murdoch task rank)
          (only (murdoch task takers) explanation-free explanation-capable))
  (include "holding.scm"))
