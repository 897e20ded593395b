;;> The lab's multicast group: authentic datagrams that cannot be
;;> replayed, and beacons that keep the live set.

(define-library (murdoch remote group)
  (export start-group! delivery-mode send-datagram!
          group-call? group-call-sender group-call-id group-call-kind
          group-call-proc-code group-call-args-code)
  (import (scheme base) (scheme write) (srfi 18) (srfi 69)
          (only (chibi) call-with-output-string) (chibi net) (murdoch sys)
          (murdoch wire) (murdoch lab) (murdoch remote aspace) (murdoch remote worker))
  (include "group.scm"))
