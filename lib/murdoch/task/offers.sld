;;> Offers: a robot whose subjects are freed offers itself to the tasks
;;> that wait for it, best rank first (note-waiters!, and robot-freed!'s
;;> round), and receive-offer is what a waiting task's poser answers.

(define-library (murdoch task offers)
  (export open-offering! receive-offer offered-to-others note-waiters! robot-freed!
          offer-on-joining!)
  (import (scheme base) (scheme cxr) (srfi 1) (srfi 18) (srfi 132)
          (murdoch sys) (murdoch code) (murdoch wire) (murdoch lab) (murdoch remote)
          (only (murdoch pubsub) request subscription-statuses offer-subjects!)
          (murdoch task record) (murdoch task rank))
  (include "offers.scm"))
