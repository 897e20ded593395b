;;> The wire: remote errors, netstrings and the nesting scan, HMAC,
;;> multicast sockets, connecting with a timeout, and frames.

(define-library (murdoch wire)
  (export open-connection socket-port make-message message-id message-field check-message
          check-datagram start-wire! frame-text message-without-id spliced-text
          write-frame! write-message! send-frame! read-frame open-frame max-frame frame-fail
          protocol-fault? fault-message log-fault datagram-bytes
          open-datagram-text datagram-head datagram-from? hmac-sha256
          open-multicast-socket read-netstring write-netstring remote-error
          protocol-fail error-message error-message-naming remote-error?
          remote-error-uid remote-error-message remote-timeout-error?
          remote-unreachable-error? remote-raised-error? remote-protocol-error?)
  (import (murdoch wire connect) (murdoch wire frame) (murdoch wire hmac)
          (murdoch wire multicast) (murdoch wire netstring) (murdoch wire remote-error)))
