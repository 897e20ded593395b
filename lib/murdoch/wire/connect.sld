;;> A TCP connect that gives up at a timeout: \scheme{open-connection},
;;> the non-blocking replacement of (chibi net)'s \scheme{open-net-io}.
;;> The C is lib/murdoch/wire/connect.stub and nonblocking-connect.c, built into
;;> lib/murdoch/wire/connect.so by \scheme{make native}; the waiting is
;;> lib/murdoch/wire/connect.scm.
;;>
;;> \procedure{(socket-port socket)}
;;> The local port \var{socket} is bound to: for a listener bound to port
;;> 0, the free one the kernel chose.

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
