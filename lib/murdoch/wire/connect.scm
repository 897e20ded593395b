;;;; A TCP connect that gives up at a timeout, pausing only its own green
;;;; thread: connect.stub starts a non-blocking connect, and port-wait!
;;;; waits for the socket to turn writable, which is when a connect ends.

;;> \procedure{(open-connection host port seconds)}
;;> Connects to \var{host}'s TCP \var{port} within \var{seconds}, blocking
;;> no other thread: \scheme{(list in out)}, or a string saying why not.
;;> Only wrong arguments raise; a name not in /etc/hosts may ask DNS.
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

;; Seconds to the millisecond, as a person writes them (0.99996 s is 1 s).
(define (seconds-text seconds)
  (let ((rounded (/ (round (* 1000 seconds)) 1000)))
    (number->string (if (integer? rounded) (exact rounded) rounded))))

;; Closes a socket that has no ports yet through one, which marks its
;; fileno closed, lest the collector close the number again later.
(define (close-socket sock why)
  (close-port (open-input-file-descriptor sock))
  why)
