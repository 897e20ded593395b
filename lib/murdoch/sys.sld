;;> The process: green threads over ppoll, the heap guard, the process's
;;> name and death signal, one-line logs, one clock and one way to wait.
;;> exports what the families above use of them.

(define-library (murdoch sys)
  (export start-heap-guard! heap-on-huge-pages! utc-seconds set-log-name!
          stamp-log-lines! log-note log-warn condition-message set-process-name!
          die-with-parent! others-runnable? cpu-contended? monotonic-seconds wall-microseconds
          stack-guard-tripped? port-wait! poller-port poller-watch!
          poller-unwatch! poller-release! poller-buffered poller-ready
          poller-frames! lock! unlock! unlocked unlock-waiting! cell-value with-lock
          with-lock-by seconds-until undo-on-raise undo-begun! undo-ended map-guarded make-mailbox
          mailbox-put! mailbox-take mailbox-empty! take-mailbox!
          take-all-mailboxes! make-gathering gathering-put! gathering-wait
          define-lean-record-type)
  (import (murdoch sys guard) (murdoch sys log) (murdoch sys process)
          (murdoch sys scheduler) (murdoch sys wait) (murdoch sys record)))
