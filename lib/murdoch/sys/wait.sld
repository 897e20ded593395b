;;> Waiting with a deadline: locks, one-shot mailboxes, gatherings of
;;> answers, and undoing on a raise.  Deadlines are moments of (murdoch
;;> scheduler)'s monotonic-seconds.

(define-library (murdoch sys wait)
  (export with-lock with-lock-by seconds-until undo-on-raise
          make-mailbox mailbox-put! mailbox-take
          take-mailbox! take-all-mailboxes!
          make-gathering gathering-put! gathering-wait)
  (import (scheme base) (srfi 18) (srfi 69) (murdoch sys scheduler))
  (include "wait.scm"))
