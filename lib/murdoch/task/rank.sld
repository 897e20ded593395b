;;> Waiting and rank: a task's turn (start-task's wait, hold, priority
;;> and deadline), the lab-wide order of the waiting tasks, each one's
;;> place in it, and the waiter record of a task waiting here.

(define-library (murdoch task rank)
  (export open-line! make-turn turn? turn-wait? turn-hold? turn-priority turn-deadline
          turn-posed read-turn check-waiting-room turn-rank rank<? better-rank
          look-period
          make-waiter waiter? waiter-task waiter-components waiter-rank
          waiter-held waiter-held-set! waiter-looked waiter-looked-set!
          waiter-kept waiter-kept-set! waiter-yielded waiter-yielded-set!
          waiter-capable waiter-capable-set! waiter-capables looked-capable
          open-matching match! matched-to-others note-subjects!
          waiter-capables-set! waiter-offered waiter-offered-set! waiter-position waiter-position-set!
          waiter-why waiter-why-set! waiter-never waiter-never-set!
          waiter-excluded waiter-excluded-set! waiter-news waiter-news-set!
          waiter-bell waiter-bell-set! waiters add-waiter! drop-waiter! in-rank-order
          news-kind offer? offer-reply offer-uid give-way-uid tell-waiter!
          take-news! answer-offers! held-index held-winner held-type held-uid
          held-uids place-in-line line-ranks-now line-ranks-length waiting-ranks waiting-there?
          waiting-there-poser waiting-there-rank
          waiting-there-held waiting-elsewhere waiting-at-others lab-holders
          know-poser! ask-posers wants? waiting-entries waiting-entry
          wanting-rank
          wanting-poser wanting-id
          make-try-turn try-turn? try-turn-waiter try-turn-claim try-turn-bell
          in-try-order let-in join-try-turns! leave-try-turns! claimed-by-others?)
  (import (scheme base) (scheme cxr) (srfi 1) (srfi 18) (srfi 132) (murdoch sys)
          (murdoch lab) (murdoch remote) (murdoch task pose-task)
          (only (murdoch pubsub) request capability-layout) (murdoch task record))
  (include "rank.scm" "try-turns.scm"))
