;;> Waiting with a deadline: locks, one-shot mailboxes, gatherings of
;;> answers, and undoing on a raise.  Deadlines are moments of (murdoch
;;> scheduler)'s monotonic-seconds.

(define-library (murdoch sys wait)
  (export lock! unlock! unlocked unlock-waiting! cell-value wind with-lock with-lock-by
          lock-ranks
          seconds-until undo-on-raise undo-begun! undo-ended map-guarded
          make-mailbox mailbox-put! mailbox-take mailbox-empty!
          take-mailbox! take-all-mailboxes!
          make-gathering gathering-put! gathering-wait)
  (import (scheme base) (only (chibi) %dk make-constructor slot-set!) (only (chibi ast) type-of) (murdoch sys record) (only (meta) find-module module-env)
          (only (scheme eval) eval) (only (scheme process-context) get-environment-variable)
          (only (scheme write) write) (only (scheme file) open-output-file)
          (only (chibi) call-with-output-string) (only (chibi process) current-process-id)
          (srfi 18) (srfi 69) (murdoch sys scheduler))
  (include "wait.scm"))
