;;; (murdoch wire connect): a connect that answers ports, says why it failed, and
;;; gives up at its timeout while the process's other threads run; and
;;; sockets of failed connects that the collector never closes twice.
;;; Values and order only: durations are not asserted.
(import (scheme base) (srfi 18) (chibi test)
        (only (chibi net) accept listen get-address-info
              address-info-address address-info-address-length)
        (only (chibi filesystem) open-input-file-descriptor
              open-output-file-descriptor directory-files)
        (only (chibi ast) gc) (only (chibi process) alarm)
        (murdoch wire connect)
        (only (murdoch testing harness) listen-on-free-port))

;; A connect that never gives up fails the run instead of stalling it.
(alarm 120)

(define (start thunk)
  (thread-start! (make-thread thunk)))

(define (send! out text)
  (write-bytevector (string->utf8 text) out)
  (flush-output-port out))

(define (read-text n in)
  (let ((bv (read-bytevector n in)))
    (if (eof-object? bv) bv (utf8->string bv))))

;; How many descriptors the process has open (Linux).
(define (descriptors)
  (length (directory-files "/proc/self/fd")))

;; The same, once the collector has closed those of ports nothing refers to.
(define (open-descriptors)
  (gc)
  (descriptors))

(define (close-both io)
  (close-input-port (car io))
  (close-output-port (cadr io)))

;; The next connection to listener (a (socket . port) pair), as (in out).
(define (accept-one listener)
  (let* ((addr (get-address-info "127.0.0.1" (cdr listener)))
         (fd (accept (car listener) (address-info-address addr)
                     (address-info-address-length addr))))
    (list (open-input-file-descriptor fd #t)
          (open-output-file-descriptor fd #t))))

;; A connection to listener from host, as (client server), each (in out).
(define (connection-on listener host)
  (let* ((server (start (lambda () (accept-one listener))))
         (client (open-connection host (cdr listener) 5)))
    (list client (thread-join! server))))

;; The client sends "ping", the server answers "pong"; both ends are then
;; closed.  Answers what each end read.
(define (exchange connection)
  (let ((client (car connection))
        (server (cadr connection)))
    (send! (cadr client) "ping")
    (let* ((got (read-text 4 (car server)))
           (answer (begin (send! (cadr server) "pong")
                          (read-text 4 (car client)))))
      (close-both client)
      (close-both server)
      (list got answer))))

;; 1 for a connect that failed, 0 for one that did not.
(define (failed result)
  (if (string? result) 1 0))

(define (ping-pong listener host)
  (exchange (connection-on listener host)))

;; A port that a listener of ours held a moment ago and nothing holds now.
;; The listener is closed through a port, which marks its fileno closed.
(define (closed-port)
  (let ((listener (listen-on-free-port)))
    (close-port (open-input-file-descriptor (car listener)))
    (cdr listener)))

;; A listener whose accept queue holds one connection, never accepted, and
;; no more: Linux drops the SYN of any further connect, which then stays
;; pending, as with a host that does not answer.  Answers (listener
;; . port) and the connection that fills the queue.
(define (full-listener)
  (let ((listener (listen-on-free-port)))
    (listen (car listener) 0)            ; listen again: the queue's new size
    (list listener (open-connection "127.0.0.1" (cdr listener) 5))))

;; Calls thunk while a thread ticks every 10 ms; answers thunk's value and
;; the ticks counted when it returned.  A thunk that held the process would
;; leave at most one tick, squeezed in between its return and the count.
(define (with-ticker thunk)
  (let* ((ticks 0)
         (ticker (start (lambda ()
                          (let tick ()
                            (thread-sleep! 0.01)
                            (set! ticks (+ ticks 1))
                            (tick)))))
         (value (thunk))
         (seen ticks))
    (thread-terminate! ticker)
    (list value seen)))

(test-begin "connect")

(define listener (listen-on-free-port))

(test "a connect to 127.0.0.1 carries bytes both ways" '("ping" "pong")
  (ping-pong listener "127.0.0.1"))

(test "localhost is a host too" '("ping" "pong")
  (ping-pong listener "localhost"))

(test "closing both ports closes the socket: the server reads end of file"
    #t
  (let* ((server (start (lambda ()
                          (let* ((io (accept-one listener))
                                 (end (eof-object? (read-u8 (car io)))))
                            (close-both io)
                            end))))
         (io (open-connection "127.0.0.1" (cdr listener) 5)))
    (close-both io)
    (thread-join! server)))

(test "and frees its descriptor at once, not when collected" #t
  (let* ((before (begin (gc) (descriptors)))
         (c (connection-on listener "127.0.0.1")))
    (close-both (car c))
    (close-both (cadr c))
    (= before (descriptors))))

(test "a port nothing listens on refuses" "connection refused"
  (open-connection "127.0.0.1" (closed-port) 5))

(test-assert "a host that does not resolve is a string saying why"
  (string? (open-connection "no-such-host.invalid" 80 5)))

(define full (full-listener))
(define full-port (cdr (car full)))

(test-assert "the connection that fills the queue is up" (pair? (cadr full)))

(let ((result (with-ticker
               (lambda () (open-connection "127.0.0.1" full-port 0.3)))))
  (test "a connect nobody answers gives up at its timeout"
      "no connection within 0.3 s"
    (car result))
  (test-assert "another thread ran meanwhile" (>= (cadr result) 2)))

;; Failed connects leave no fileno behind: one would close its number when
;; collected, and the number is by then another socket's.  Sockets opened
;; after the failures take those numbers; all must work after collections.
(test-group "after failed connects and collections"
  (let* ((before (connection-on listener "127.0.0.1"))
         (refused (closed-port))
         (open-before (open-descriptors))
         (failures
          (let loop ((i 0) (n 0))
            (if (= i 100)
                n
                (loop (+ i 1)
                      (+ n (failed (open-connection "127.0.0.1" refused 5))
                         (failed
                          (open-connection "127.0.0.1" full-port 0.005)))))))
         (open-after (open-descriptors))
         (later (listen-on-free-port))
         (after (connection-on later "127.0.0.1")))
    (gc) (gc) (gc)
    (test "every connect failed" 200 failures)
    (test "and left no socket open" open-before open-after)
    (test "a connection made before still carries bytes" '("ping" "pong")
      (exchange before))
    (test "a connection made after still carries bytes" '("ping" "pong")
      (exchange after))
    (test "the listener made before still accepts" '("ping" "pong")
      (ping-pong listener "127.0.0.1"))
    (test "the listener made after still accepts" '("ping" "pong")
      (ping-pong later "127.0.0.1"))))

(test-end)
(test-exit)
