;;;; Netstring ping-pong between two Chibi processes over loopback TCP.
;;
;; Usage: tools/chibi bench/scheme-pingpong.scm [nap] [poll]
;;
;; For each mode (default: both, nap first) the process forks an echo
;; server, connects to it, and times round trips of a 4-byte netstring
;; after a warm-up.  "nap" runs Chibi's own scheduler, which naps 10 ms
;; whenever every thread is blocked; "poll" first loads (murdoch sys scheduler),
;; which the forked server inherits, so both ends wait in ppoll instead.
;; The module cannot be taken out again, so nap must come before poll.
;; Prints, per mode, the MEDIAN round trip in microseconds:
;;   bench: chibi-pingpong-rtt-nap VALUE us
;;   bench: chibi-pingpong-rtt VALUE us
;;
;; Usage: tools/chibi bench/scheme-pingpong.scm pipelined
;;
;; The floor of a sender keeping 16 calls in flight: with (murdoch
;; scheduler) at both ends, 16 netstrings are kept on their way to the echo
;; server, a new one sent as each echo comes back:
;;   bench: chibi-pipelined-throughput VALUE per-s
;;
;; Usage: tools/chibi bench/scheme-pingpong.scm fanout N [poll]
;;
;; The floor of a request to a lab of N, in Chibi: N echo servers, each a
;; Chibi process of its own as an address space is, get the netstring in
;; turn, then each echo is read; prints the MEDIAN round in microseconds:
;;   bench: chibi-fanout-NN VALUE us       the servers block in read(2)
;;   bench: chibi-fanout-poll-NN VALUE us  they wait in ppoll through
;;                                         (murdoch sys scheduler), as an
;;                                         address space waits
;; and with poll the receiver's floor, the servers' own CPU per frame
;; over the same timed rounds (each wakes in ppoll, reads one netstring
;; and writes it back), beside a lab's request-receiver-cpu-NN:
;;   bench: chibi-echo-cpu-per-frame-NN VALUE us
;; The sender waits in ppoll in both.  bench/c-pingpong N is the same in C.
;;
;; Usage: tools/chibi bench/scheme-pingpong.scm phases N
;;
;; The floor of a multicast requester's CPU over a broadcasting one's.
;; The same fan-out in ppoll, the sender's own CPU split between its two
;; phases, per peer: writing the N frames, then reading the N echoes.  In
;; rounds taking turns with those, the same servers answer one multicast
;; datagram instead, each on its connection, as an address space answers
;; a multicast call; the sender is a member of the group, as a requester
;; is, and reads its own datagram back.  The datagram's sending per peer
;; (the kernel delivers it to N sockets), and the multicast round's CPU
;; over the fan-out's:
;;   bench: chibi-fanout-write-cpu-per-peer-NN VALUE us
;;   bench: chibi-fanout-read-cpu-per-peer-NN VALUE us
;;   bench: chibi-mcast-send-cpu-per-peer-NN VALUE us
;;   bench: chibi-mcast-over-fanout-cpu-NN VALUE x

(import (scheme base) (scheme write) (scheme eval) (scheme process-context)
        (srfi 1) (srfi 18) (srfi 132)
        (chibi net) (chibi filesystem) (chibi process) (murdoch wire multicast)
        (only (chibi time) get-time-of-day timeval-seconds timeval-microseconds)
        (murdoch wire netstring) (bench echo) (bench clock)
        (only (murdoch testing harness) listen-on-free-port free-port-base tool-path
              start-process! stop-all-processes!))

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

(define (round-trip in out)
  (fan-out (list (list #f in out))))

;; One frame to each (_ in out) of ios in turn, then each echo read.
(define (fan-out ios)
  (send-to-each ios)
  (read-each ios))

(define (send-to-each ios)
  (for-each (lambda (io)
              (write-netstring payload (car (cddr io)))
              (flush-output-port (car (cddr io))))
            ios))

(define (read-each ios)
  (for-each (lambda (io)
              (unless (equal? (read-netstring (cadr io) max-frame) payload)
                (error "echo server sent back something else")))
            ios))


(define (median-time thunk trips warm-up)
  (do ((i 0 (+ i 1))) ((= i warm-up)) (thunk))
  (let loop ((i 0) (times '()))
    (if (= i trips)
        (list-ref (list-sort < times) (quotient trips 2))
        (let ((start (microseconds)))
          (thunk)
          (loop (+ i 1) (cons (- (microseconds) start) times))))))

(define (median-round-trip in out trips warm-up)
  (median-time (lambda () (round-trip in out)) trips warm-up))

;; Frames a second through the echo server, depth of them on their way at
;; any moment, after a warm-up as long.
(define (pipelined-throughput in out frames depth)
  (define (send!) (write-netstring payload out) (flush-output-port out))
  (define (take!) (read-netstring in max-frame))
  (define (run n)
    (let ((start (microseconds)))
      (do ((i 0 (+ i 1))) ((= i depth)) (send!))
      (do ((i depth (+ i 1))) ((= i n)) (take!) (send!))
      (do ((i 0 (+ i 1))) ((= i depth)) (take!))
      (/ (* n 1000000.) (- (microseconds) start))))
  (run frames)
  (exact (round (run frames))))

(define (measure mode)
  (let* ((listener+port (listen-on-free-port))
         (pid (begin (flush-output-port) (fork))))
    (cond
     ((zero? pid)
      (echo-connection (car listener+port) (cdr listener+port) #f max-frame)
      (vanish))
     (else
      ;; The listener stays open here: close-file-descriptor would leave its
      ;; fileno object marked open, and the collector would later close the
      ;; same number again, by then maybe the client's socket.
      (let* ((io (guard (e (#t (kill pid signal/kill) (waitpid pid 0) (raise e)))
                   (open-net-io "127.0.0.1" (cdr listener+port))))
             (counts (trip-counts mode))
             (rtt (if (eq? mode 'pipelined)
                      (pipelined-throughput (cadr io) (car (cddr io)) 20000 16)
                      (median-round-trip (cadr io) (car (cddr io))
                                         (car counts) (cdr counts)))))
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
     (environment '(murdoch sys scheduler))   ; loading it installs it
     (set! poll-loaded? #t)
     (report "chibi-pingpong-rtt" (measure mode)))
    ((pipelined)
     (environment '(murdoch sys scheduler))
     (set! poll-loaded? #t)
     (report "chibi-pipelined-throughput" (measure mode) "per-s"))
    (else (error "unknown mode; expected nap or poll" mode))))

;; A server (bench/echo-server.scm) serves the first connection it takes,
;; so it is not probed before (wait-for-port would be that first
;; connection): connecting is tried again for as long as a server may take
;; to start, five minutes, when 64 start at once on a machine busy with
;; others' tests.
(define (connect-to-server port)
  (let try ((tries 3000))
    (or (guard (e ((> tries 0) #f)) (open-net-io "127.0.0.1" port))
        (begin (thread-sleep! 0.1) (try (- tries 1))))))

;; (measure ios pids) with ios connected to n echo servers started as
;; processes of their own (bench/echo-server.scm), pids theirs.  With a
;; group address they also answer the datagrams sent to it, at port
;; (group-port base n), and measure is applied to ios, pids and (socket
;; . address): a socket on the group, and where to send to it.
(define (with-echo-servers n wait measure . group)
  (environment '(murdoch sys scheduler))
  (let* ((base (free-port-base))
         (group-args (if (pair? group)
                         (list (car group) (number->string (group-port base n)))
                         '()))
         (group-socket (and (pair? group)
                            (open-multicast-socket (car group) (group-port base n)
                                                   "127.0.0.1"))))
    (define pids
      (map (lambda (i)
             (start-process! (append (list (tool-path "tools/chibi")
                                           (tool-path "bench/echo-server.scm")
                                           (number->string (+ base i)) wait)
                                     group-args)
                             "/dev/null"))
           (iota n)))
    (guard (e (#t (stop-all-processes!) (raise e)))
      (let* ((ios (map (lambda (i) (connect-to-server (+ base i))) (iota n)))
             (result (if group-socket
                         (measure ios pids
                                  (cons group-socket
                                        (get-address-info (car group)
                                                          (group-port base n))))
                         (measure ios pids))))
        (stop-all-processes!)
        result))))

;; The group's port, past the n servers' in the port base's range.
(define (group-port base n) (+ base n))

;; An address no lab of the tests or benches uses; the port base keeps
;; two runs at once apart.
(define floor-group "239.255.77.11")

;; The median round of the fan-out to n servers, and the servers' CPU per
;; frame over the timed rounds: (round-us . server-us).
(define (measure-fan-out n wait)
  (with-echo-servers n wait
    (lambda (ios pids)
      (let ((trips (quotient 20000 n)))
        (do ((i 0 (+ i 1))) ((= i (quotient 1000 n))) (fan-out ios))
        (let* ((before (processes-cpu-us pids))
               (round (median-time (lambda () (fan-out ios)) trips 0)))
          (cons round (/ (- (processes-cpu-us pids) before) trips n)))))))

;; The sender's CPU per peer over rounds after a warm-up, each fan-out
;; followed by a multicast round: (write-us read-us mcast-send-us
;; mcast-us), the last two the datagram's sending and the whole round.
(define (measure-phases n)
  (with-echo-servers n "poll"
    (lambda (ios pids group)
      (let ((rounds (quotient 32000 n)) (write-us 0.) (read-us 0.)
            (send-us 0.) (mcast-us 0.))
        (do ((i 0 (+ i 1))) ((= i (quotient 1000 n)))
          (fan-out ios)
          (multicast-round ios group))
        (do ((i 0 (+ i 1))) ((= i rounds))
          (let ((t0 (own-cpu-us)))
            (send-to-each ios)
            (let ((t1 (own-cpu-us)))
              (read-each ios)
              (let ((t2 (own-cpu-us)))
                (send-datagram group)
                (let ((t3 (own-cpu-us)))
                  (read-datagram-answers ios group)
                  (set! write-us (+ write-us (- t1 t0)))
                  (set! read-us (+ read-us (- t2 t1)))
                  (set! send-us (+ send-us (- t3 t2)))
                  (set! mcast-us (+ mcast-us (- (own-cpu-us) t2))))))))
        (map (lambda (us) (/ us rounds n)) (list write-us read-us send-us mcast-us))))
    floor-group))

;; One datagram to the servers' group, (socket . address), then each
;; answer read, and the sender's own datagram, looped back to it.
(define (multicast-round ios group)
  (send-datagram group)
  (read-datagram-answers ios group))

(define (send-datagram group)
  (send (car group) payload 0 (cdr group)))

(define own-datagram (make-bytevector max-frame))

(define (read-datagram-answers ios group)
  (read-each ios)
  (receive! (car group) own-datagram))

(define (round1 x) (/ (round (* 10 x)) 10.))
(define (round2 x) (/ (round (* 100 x)) 100.))

(define (report name value . unit)
  (display "bench: ") (display name) (display " ")
  (display value) (display " ") (display (if (pair? unit) (car unit) "us"))
  (newline))

(let ((args (cdr (command-line))))
  (cond
   ((and (pair? args) (equal? (car args) "phases"))
    (let* ((n (string->number (cadr args)))
           (phases (measure-phases n))
           (suffix (string-append "-N" (number->string n))))
      (report (string-append "chibi-fanout-write-cpu-per-peer" suffix)
              (round1 (car phases)))
      (report (string-append "chibi-fanout-read-cpu-per-peer" suffix)
              (round1 (cadr phases)))
      (report (string-append "chibi-mcast-send-cpu-per-peer" suffix)
              (round1 (list-ref phases 2)))
      (report (string-append "chibi-mcast-over-fanout-cpu" suffix)
              (round2 (/ (list-ref phases 3) (+ (car phases) (cadr phases)))) "x")))
   ((and (pair? args) (equal? (car args) "fanout"))
    (let* ((n (string->number (cadr args)))
           (poll? (pair? (cddr args)))
           (measured (measure-fan-out n (if poll? "poll" "block"))))
      (report (string-append (if poll? "chibi-fanout-poll-N" "chibi-fanout-N")
                             (number->string n))
              (car measured))
      (if poll?
          (report (string-append "chibi-echo-cpu-per-frame-N" (number->string n))
                  (round1 (cdr measured))))))
   (else
    (for-each run (if (null? args) '(nap poll) (map string->symbol args))))))
