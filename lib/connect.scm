;;;; A TCP connect that gives up at a timeout without holding the process.
;;
;; The socket is connected in C (lib/connect.c), non-blocking; this side
;; only looks every millisecond whether the connect is done, and sleeps its
;; own green thread in between, so the process's other threads run on.

;;> \procedure{(open-connection host port seconds)}
;;> Connects to TCP \var{port} of \var{host} (an IPv4 address or a name
;;> such as "localhost"), waiting at most \var{seconds} and blocking no
;;> other thread meanwhile.  Answers \scheme{(list in out)}, an input and
;;> an output port on the connected socket, which closing both closes; or,
;;> when there is no connection, a string saying why, such as
;;> "connection refused", "no such host" or "no connection within 0.3 s",
;;> for the caller to put after the peer's name.  Only wrong arguments
;;> raise.  Resolving a name that is not an address nor in /etc/hosts may
;;> ask DNS, which blocks the process.
(define (open-connection host port seconds)
  (let ((fd (connect-start host port)))
    (if (string? fd)
        fd
        (await-connect fd (+ (monotonic-seconds) seconds) seconds))))

;; A millisecond is little next to the timeouts of a remote call, and the
;; first look comes early enough for a connect on the loopback or a LAN.
(define (await-connect fd deadline seconds)
  (cond
   ((connect-poll fd))
   ((> (monotonic-seconds) deadline)
    (connect-abandon fd)
    (string-append "no connection within " (number->string seconds) " s"))
   (else
    (thread-sleep! 0.001)
    (await-connect fd deadline seconds))))
