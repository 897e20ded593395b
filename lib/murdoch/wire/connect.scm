;;;; A TCP connect that gives up at a timeout without holding the process.
;;
;; The socket is made and closed here, as (chibi net) makes and closes
;; its own; the C of connect.stub starts its connect, non-blocking, and says
;; when the connect is done.  This side waits for the socket to turn writable,
;; which is when a connect ends, pausing only its own green thread
;; (port-wait!), so the process's other threads run on.

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
  (let ((sock (socket address-family/inet socket-type/stream 0)))
    (if (not (fileno? sock))
        "no socket to connect with"
        (begin
          (set-file-descriptor-status!
           sock (bitwise-ior open/non-block (get-file-descriptor-status sock)))
          (let ((started (connect-start sock host port)))
            (if (string? started)
                (close-socket sock started)
                (await-connect sock (open-output-file-descriptor sock #t)
                               (+ (monotonic-seconds) seconds) seconds)))))))

;; out is the socket's output port, the one a writable socket wakes.
(define (await-connect sock out deadline seconds)
  (let ((done (connect-poll sock)))
    (cond
     ((string? done) (close-port out) done)
     (done (list (open-input-file-descriptor sock #t) out))
     ((>= (monotonic-seconds) deadline)
      (close-port out)
      (string-append "no connection within " (seconds-text seconds) " s"))
     (else
      (port-wait! out (- deadline (monotonic-seconds)))
      (await-connect sock out deadline seconds)))))

;; Seconds to the millisecond, as a person would write them: a caller's
;; remaining time of 0.99996 s is 1 s.
(define (seconds-text seconds)
  (let ((rounded (/ (round (* 1000 seconds)) 1000)))
    (number->string (if (integer? rounded) (exact rounded) rounded))))

;; Closes a socket that has no ports yet, through one: that marks its
;; fileno closed, where close-file-descriptor would leave it marked open
;; for the collector to close the number again, whoever has it by then.
;; Answers why.
(define (close-socket sock why)
  (close-port (open-input-file-descriptor sock))
  why)
