;;> The wire: remote errors, netstrings and the nesting scan, HMAC,
;;> multicast sockets, connecting with a timeout, and frames.
;;> Its members are each a library of their own in wire/.

(define-library (murdoch wire)
  (export open-connection socket-port message-kinds make-message message-id
          check-message check-datagram start-wire! frame-text message-without-id
          spliced-text
          write-frame! send-frame! read-frame
          open-frame max-frame frame-fail parse-message protocol-fault? fault-message
          log-fault datagram-bytes open-datagram-text datagram-head datagram-from?
          hmac-sha256 hmac-sha256-sign
          hmac-sha256-write! hmac-sha256-open open-multicast-socket read-netstring
          write-netstring
          buffered-byte-count reset-output-string! nests-within? fixnum->decimal
          netstring-error? netstring-error-message remote-error protocol-fail
          error-message error-message-naming remote-error?
          remote-error-uid remote-error-message remote-timeout-error?
          remote-unreachable-error? remote-raised-error? remote-protocol-error?)
  (import (murdoch wire connect) (murdoch wire frame) (murdoch wire hmac)
          (murdoch wire multicast) (murdoch wire netstring) (murdoch wire remote-error)))
