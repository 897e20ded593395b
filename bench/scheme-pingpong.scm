;;;; Netstring ping-pong between two Chibi processes over loopback TCP.
;;
;; Usage: tools/chibi bench/scheme-pingpong.scm [nap] [poll]
;;
;; For each mode (default: both, nap first) the process forks an echo
;; server, connects to it, and times round trips of a 4-byte netstring
;; after a warm-up.  "nap" runs Chibi's own scheduler, which naps 10 ms
;; whenever every thread is blocked; "poll" first loads (murdoch scheduler),
;; which the forked server inherits, so both ends wait in ppoll instead.
;; The module cannot be taken out again, so nap must come before poll.
;; Prints, per mode, the MEDIAN round trip in microseconds:
;;   bench: chibi-pingpong-rtt-nap VALUE us
;;   bench: chibi-pingpong-rtt VALUE us

(import (scheme base) (scheme write) (scheme eval) (scheme process-context)
        (srfi 18) (srfi 132)
        (chibi net) (chibi filesystem) (chibi process)
        (only (chibi time) get-time-of-day timeval-seconds timeval-microseconds)
        (murdoch netstring)
        (only (murdoch testing) listen-on-free-port))

(define payload (bytevector 112 105 110 103))   ; "ping"
(define max-frame 64)

;; (trips . warm-up) per mode: the nap mode costs ~11 ms a trip.
(define (trip-counts mode)
  (if (eq? mode 'nap) '(200 . 10) '(2000 . 100)))

(define (microseconds)
  (let ((tv (car (get-time-of-day))))
    (+ (* (timeval-seconds tv) 1000000) (timeval-microseconds tv))))

;; A forked child must not leave through exit: Chibi's exit and
;; emergency-exit both call libc's exit, which moves the file offset the
;; child shares with the parent's reader of this script.
(define (vanish)
  (kill (current-process-id) signal/kill))

(define (echo-server listener port)
  (let* ((addr (get-address-info "127.0.0.1" port))
         (sock (accept listener (address-info-address addr)
                       (address-info-address-length addr)))
         (in (open-input-file-descriptor sock))
         (out (open-output-file-descriptor sock)))
    (let loop ()
      (let ((frame (read-netstring in max-frame)))
        (unless (eof-object? frame)
          (write-netstring frame out)
          (flush-output-port out)
          (loop))))))

(define (round-trip in out)
  (write-netstring payload out)
  (flush-output-port out)
  (unless (equal? (read-netstring in max-frame) payload)
    (error "echo server sent back something else")))

(define (median-round-trip in out trips warm-up)
  (do ((i 0 (+ i 1))) ((= i warm-up)) (round-trip in out))
  (let loop ((i 0) (times '()))
    (if (= i trips)
        (list-ref (list-sort < times) (quotient trips 2))
        (let ((start (microseconds)))
          (round-trip in out)
          (loop (+ i 1) (cons (- (microseconds) start) times))))))

(define (measure mode)
  (let* ((listener+port (listen-on-free-port))
         (pid (begin (flush-output-port) (fork))))
    (cond
     ((zero? pid)
      (echo-server (car listener+port) (cdr listener+port))
      (vanish))
     (else
      ;; The listener stays open here: close-file-descriptor would leave its
      ;; fileno object marked open, and the collector would later close the
      ;; same number again, by then maybe the client's socket.
      (let* ((io (guard (e (#t (kill pid signal/kill) (waitpid pid 0) (raise e)))
                   (open-net-io "127.0.0.1" (cdr listener+port))))
             (counts (trip-counts mode))
             (rtt (median-round-trip (cadr io) (car (cddr io))
                                     (car counts) (cdr counts))))
        ;; Closing the connection ends the server.
        (close-output-port (car (cddr io)))
        (close-input-port (cadr io))
        (waitpid pid 0)
        rtt)))))

(define poll-loaded? #f)

(define (run mode)
  (case mode
    ((nap)
     (if poll-loaded? (error "nap must be measured before poll"))
     (report "chibi-pingpong-rtt-nap" (measure mode)))
    ((poll)
     (environment '(murdoch scheduler))   ; loading it installs it
     (set! poll-loaded? #t)
     (report "chibi-pingpong-rtt" (measure mode)))
    (else (error "unknown mode; expected nap or poll" mode))))

(define (report name value)
  (display "bench: ") (display name) (display " ")
  (display value) (display " us") (newline))

(let ((modes (map string->symbol (cdr (command-line)))))
  (for-each run (if (null? modes) '(nap poll) modes)))
