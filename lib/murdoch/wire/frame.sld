;;> The wire: the table of message kinds, and frames -- netstrings
;;> carrying a MAC'd S-expression -- and datagrams.  The protocol is
;;> written at the head of lib/murdoch/wire/frame.scm.

(define-library (murdoch wire frame)
  (export message-kinds make-message message-id message-field check-message check-datagram
          start-wire! frame-text message-without-id spliced-text write-frame!
          write-message! send-frame! read-frame
          open-frame max-frame
          frame-fail parse-message protocol-fault? fault-message log-fault
          datagram-bytes open-datagram-text datagram-head datagram-from?)
  (import (scheme base) (scheme write) (rename (only (chibi) read) (read read-datum))
          (only (chibi) string-size call-with-output-string) (only (srfi 18) make-mutex)
          (murdoch sys) (murdoch lab)
          (murdoch wire remote-error) (murdoch wire netstring) (murdoch wire hmac))
  (include "frame.scm"))
