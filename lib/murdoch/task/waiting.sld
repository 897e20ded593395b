;;> Tasks that wait their turn: negotiate-turn negotiates a task, and one
;;> started with wait #t waits, trying again when a robot offers itself,
;;> until it wins its robots, its deadline passes or it is cancelled.

(define-library (murdoch task waiting)
  (export open-looking! negotiate-turn move-up!)
  (import (scheme base) (scheme char) (scheme cxr) (srfi 1) (srfi 18) (srfi 132)
          (murdoch sys) (murdoch code) (murdoch wire) (murdoch lab) (murdoch remote)
          (murdoch task progress) (murdoch task pose-task)
          (only (murdoch pubsub) subscribe unsubscribe publish capability-layout
                request-audience)
          (only (murdoch task takers) explain-components explanation-lines explanation-line
                explanation-free explanation-capable)
          (murdoch task record) (murdoch task rank) (murdoch task offers)
          (murdoch task holding))
  (include "waiting.scm"))
