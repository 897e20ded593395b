;;> \scheme{open-connection}, a TCP connect that gives up at a timeout, in
;;> place of (chibi net)'s \scheme{open-net-io}.  C: connect.stub and
;;> nonblocking-connect.c.
;;> \procedure{(socket-port socket)} The local port \var{socket} is bound to.

(define-library (murdoch wire connect)
  (export open-connection socket-port)
  (import (scheme base) (srfi 18) (srfi 151)
          (only (chibi net) socket address-family/inet socket-type/stream)
          (only (chibi) fileno?)
          (only (chibi filesystem) open-input-file-descriptor
                open-output-file-descriptor get-file-descriptor-status
                set-file-descriptor-status! open/non-block)
          (only (murdoch sys) monotonic-seconds port-wait!))
  (include-shared "connect")
  (include "connect.scm"))
