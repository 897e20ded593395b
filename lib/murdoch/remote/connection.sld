;;> The caller's side of the wire: one greeted connection to each address
;;> space called, and the poller that reads them all.

(define-library (murdoch remote connection)
  (export open-connections! connection-to send-call! give-up-call! send-datagram-answer!
          make-pending-call pending-call? pending-call-uid
          pending-call-connection pending-call-id pending-call-answer
          answer-call! watch-served! unwatch-served!)
  (import (only (murdoch code) make-logged-thread)
          (scheme base) (srfi 18) (srfi 69) (only (chibi string) string-prefix?)
          (only (chibi) port-fileno)
          (murdoch sys) (murdoch wire) (murdoch lab)
          (murdoch remote aspace))
  (include "connection.scm"))
