;;> A peer that speaks the wire by hand, for what a well-behaved peer never
;;> sends: the tests of bad frames and of hostile peers.
(define-library (murdoch testing raw)
  (export raw-connect raw-send! raw-closed? raw-close! framed frame-mac
          hello-text hello-frame welcomed-raw-connect counted raw-answer
          text-of)
  (import (scheme base) (scheme read) (scheme write)
          (chibi net)
          (only (murdoch wire) read-netstring write-netstring hmac-sha256))
  (include "raw.scm"))
