;;; (murdoch sys scheduler): with the wrapper installed, threads blocked on
;;; descriptors wake when data comes, sleepers and timeouts wake in order,
;;; and runnable threads run.  Values and order only: durations are not
;;; asserted, a loaded machine stretches them.
;;;
;;; The data comes from a forked peer process that writes when told, so that
;;; it arrives while every thread of this process is blocked: that is the
;;; case where the wrapper, not Chibi's own scheduler, does the waiting.
(import (scheme base) (scheme eval) (srfi 18) (srfi 132) (srfi 151)
        (chibi test) (chibi net) (chibi filesystem) (chibi process)
        (only (chibi time) get-time-of-day timeval-seconds timeval-microseconds)
        (only (chibi ast) thread-interrupt!)
        (murdoch sys scheduler)
        (only (murdoch testing harness) listen-on-free-port))

;; A scheduler that never wakes fails the run instead of stalling it.
(alarm 120)

(define (nonblocking! fd)
  (set-file-descriptor-status!
   fd (bitwise-ior (get-file-descriptor-status fd) open/non-block))
  fd)

;; Both ends of a Unix socket pair, non-blocking as Chibi's threads want.
(define (channel)
  (map nonblocking! (open-socket-pair address-family/unix socket-type/stream 0)))

;; ctl carries orders to the peer; d1 and d2 carry its data back; nothing is
;; ever written to quiet, so a thread reading it stays blocked on it.
(define ctl (channel))
(define d1 (channel))
(define d2 (channel))
(define quiet (channel))
;; (socket . port): kept whole for the whole run, so that the collector
;; never closes the listener.
(define listener (listen-on-free-port))

;;; The peer

;; A forked child must not leave through exit: Chibi's exit and
;; emergency-exit both call libc's exit, which moves the file offset the
;; child shares with the parent's reader of this file.
(define (vanish)
  (kill (current-process-id) signal/kill))

(define (send! out text)
  (write-bytevector (string->utf8 text) out)
  (flush-output-port out))

(define (connect-and-send! text)
  (let ((io (open-net-io "127.0.0.1" (cdr listener))))
    (send! (car (cddr io)) text)))

(define (obey order d1-out d2-out)
  (case order
    ((#\a) (send! d1-out "hello"))
    ((#\t) (send! d1-out "abc"))
    ((#\b) (send! d2-out "world"))
    ((#\p) (send! d1-out "hel"))
    ((#\q) (send! d1-out "lo"))
    ((#\c) (connect-and-send! "hi"))
    ((#\s) (kill (parent-process-id) signal/user1))))

;; Ends at end of file on ctl, which comes when the parent exits or dies,
;; because the peer closes its own copy of the parent's end first.
(define (run-peer)
  (close-file-descriptor (car ctl))
  (let ((in (open-input-file-descriptor (cadr ctl)))
        (d1-out (open-output-file-descriptor (cadr d1)))
        (d2-out (open-output-file-descriptor (cadr d2))))
    (let loop ()
      (let ((order (read-u8 in)))
        (unless (eof-object? order)
          (obey (integer->char order) d1-out d2-out)
          (loop))))))

;; Forked before any thread is made, so the peer has none to run.
(define peer
  (let ((pid (fork)))
    (when (zero? pid)
      (guard (e (#t (vanish))) (run-peer))
      (vanish))
    pid))

;;; The test's side

(define ctl-out (open-output-file-descriptor (car ctl)))
(define d1-in (open-input-file-descriptor (car d1)))
(define d2-in (open-input-file-descriptor (car d2)))
(define quiet-in (open-input-file-descriptor (car quiet)))

(define (tell-peer order)
  (write-u8 (char->integer order) ctl-out)
  (flush-output-port ctl-out))

(define (start thunk)
  (thread-start! (make-thread thunk)))

(define (read-text n in)
  (utf8->string (read-bytevector n in)))

(define (block-forever)
  (read-u8 quiet-in))

(define (now)
  (let ((tv (car (get-time-of-day))))
    (+ (timeval-seconds tv) (/ (timeval-microseconds tv) 1000000.))))

;; Writes size bytes of 7, in chunks, as fast as the socket takes them.
(define (write-sevens fd size)
  (let ((out (open-output-file-descriptor fd))
        (chunk (make-bytevector 4096 7)))
    (do ((sent 0 (+ sent 4096)))
        ((>= sent size))
      (write-bytevector chunk out)
      (flush-output-port out))))

;; Reads size bytes; their count and their sum.
(define (sum-bytes fd size)
  (let ((in (open-input-file-descriptor fd)))
    (let loop ((got 0) (sum 0))
      (if (= got size)
          (list got sum)
          (let ((bv (read-bytevector (min 8192 (- size got)) in)))
            (loop (+ got (bytevector-length bv))
                  (+ sum (bytevector-sum bv))))))))

(define (bytevector-sum bv)
  (do ((i 0 (+ i 1))
       (sum 0 (+ sum (bytevector-u8-ref bv i))))
      ((= i (bytevector-length bv)) sum)))

;; Each sleeper sleeps until base + its delay, base being shared, so the
;; order of wake-up does not depend on when each thread got to run.
(define (wake-order delays-ms)
  (let* ((woken '())
         (base (+ (now) 0.3))
         (sleeper
          (lambda (ms)
            (start (lambda ()
                     (thread-sleep! (max 0 (- (+ base (/ ms 1000.)) (now))))
                     (set! woken (cons ms woken)))))))
    (for-each thread-join! (map sleeper delays-ms))
    (reverse woken)))

;; Lets the thread run until it owns the mutex and blocks.
(define (wait-until-owned mutex thread)
  (unless (eq? (mutex-state mutex) thread)
    (thread-yield!)
    (wait-until-owned mutex thread)))

(test-begin "scheduler")

(test "importing the library installs the wrapper" #t
  (poll-scheduler-installed?))

(test "a thread blocked reading a socket wakes when the peer writes" "hello"
  (let ((reader (start (lambda () (read-text 5 d1-in)))))
    (thread-yield!)
    (tell-peer #\a)
    (thread-join! reader)))

(test "two threads blocked on two sockets both get their data"
    '("hello" "world")
  (let ((r1 (start (lambda () (read-text 5 d1-in))))
        (r2 (start (lambda () (read-text 5 d2-in)))))
    (thread-yield!)
    (tell-peer #\b)
    (tell-peer #\a)
    (list (thread-join! r1) (thread-join! r2))))

(test "a reader that gets part of a write, then the rest" "hello"
  (let ((reader (start (lambda () (read-text 5 d1-in)))))
    (tell-peer #\p)
    (thread-sleep! 0.05)
    (tell-peer #\q)
    (thread-join! reader)))

(test "accept wakes when a client connects" "hi"
  (let* ((addr (get-address-info "127.0.0.1" (cdr listener)))
         (server
          (start (lambda ()
                   (let ((sock (accept (car listener)
                                       (address-info-address addr)
                                       (address-info-address-length addr))))
                     (read-text 2 (open-input-file-descriptor sock)))))))
    (thread-yield!)
    (tell-peer #\c)
    (thread-join! server)))

(test "a sleep ends while another thread waits on a socket" '(slept "hello")
  (let* ((events '())
         (reader (start (lambda ()
                          (let ((text (read-text 5 d1-in)))
                            (set! events (cons text events))))))
         (sleeper (start (lambda ()
                           (thread-sleep! 0.05)
                           (set! events (cons 'slept events))
                           (tell-peer #\a)))))
    (thread-join! sleeper)
    (thread-join! reader)
    (reverse events)))

(test "three threads blocked on one socket get a byte each" '(97 98 99)
  (let ((readers (map (lambda (i) (start (lambda () (read-u8 d1-in))))
                      '(1 2 3))))
    (thread-yield!)
    (tell-peer #\t)
    (list-sort < (map thread-join! readers))))

(test "a thread ends while another waits on a socket" '(ended "hello")
  (let* ((events '())
         (ender (start (lambda ()
                         (thread-sleep! 0.05)
                         (tell-peer #\a)
                         (set! events (cons 'ended events))))))
    (let ((text (read-text 5 d1-in)))
      (thread-join! ender)
      (reverse (cons text events)))))

(test "a thread ends while another sleeps" '(ended woke)
  (let* ((events '())
         (ender (start (lambda ()
                         (thread-sleep! 0.02)
                         (set! events (cons 'ended events))))))
    (thread-sleep! 0.1)
    (set! events (cons 'woke events))
    (thread-join! ender)
    (reverse events)))

(test-assert "a thread blocked on a socket can be terminated and joined"
  (let ((reader (start block-forever)))
    (thread-yield!)
    (thread-terminate! reader)
    (guard (e (#t #t))
      (thread-join! reader)
      #t)))

(test "a megabyte crosses a socket pair between two threads"
    (list (* 1024 1024) (* 7 1024 1024))
  (let* ((ends (channel))
         (size (* 1024 1024))
         (writer (start (lambda () (write-sevens (car ends) size))))
         (total (sum-bytes (cadr ends) size)))
    (thread-join! writer)
    total))

(test "a receive with a timeout on a silent socket gives up" #f
  (receive/non-blocking (car quiet) 16 0.05))

(test "sleepers started shortest last wake in deadline order"
    '(0 20 40 60 80 100 120 140)
  (wake-order '(140 120 100 80 60 40 20 0)))

(test "sleepers started in shuffled order wake in deadline order"
    '(0 20 40 60 80 100 120 140 160 180)
  (wake-order '(100 20 180 60 0 140 40 160 120 80)))

(test "mutex-lock! with a timeout gives up on a held mutex" '(#f #t)
  (let* ((m (make-mutex))
         (holder (start (lambda () (mutex-lock! m) (block-forever)))))
    (wait-until-owned m holder)
    (let ((locked (mutex-lock! m 0.05)))
      (list locked (eq? (mutex-state m) holder)))))

(test "mutex-lock! with a timeout gets a mutex released in time" #t
  (let* ((m (make-mutex))
         (holder (start (lambda ()
                          (mutex-lock! m)
                          (thread-sleep! 0.05)
                          (mutex-unlock! m)))))
    (wait-until-owned m holder)
    (mutex-lock! m 60)))

(test "thread-join! with a timeout returns the timeout value" 'timed-out
  (thread-join! (start block-forever) 0.05 'timed-out))

(test "thread-join! with a timeout gets a result that comes in time" 'done
  (thread-join! (start (lambda () (thread-sleep! 0.05) 'done)) 60 'timed-out))

(test "a condition variable signalled from another thread" '(signalled #t)
  (let ((m (make-mutex))
        (cv (make-condition-variable))
        (state 'waiting))
    (mutex-lock! m)
    (start (lambda ()
             (thread-sleep! 0.05)
             (mutex-lock! m)
             (set! state 'signalled)
             (condition-variable-signal! cv)
             (mutex-unlock! m)))
    (let ((woken (mutex-unlock! m cv)))
      (list state woken))))

(test "waiting on a condition variable nobody signals times out" #f
  (let ((m (make-mutex)))
    (mutex-lock! m)
    (mutex-unlock! m (make-condition-variable) 0.05)))

(test "a runnable thread runs while others wait on sockets" '(200000 "hello")
  (let* ((reader (start (lambda () (read-text 5 d1-in))))
         (busy (start (lambda ()
                        (let count ((i 0))
                          (if (< i 200000) (count (+ i 1)) i))))))
    (let ((n (thread-join! busy)))
      (tell-peer #\a)
      (list n (thread-join! reader)))))

;; A loop of a few instructions, counted by another thread at each of
;; its turns: Chibi's own slice of 500 instructions lets it round about 30
;; times a turn, the wrapper's 5000 about 300.
(test-assert "a thread runs ten times Chibi's slice before the next one's turn"
  (let* ((count 0)
         (stop #f)
         (busy (start (lambda ()
                        (let loop ()
                          (set! count (+ count 1))
                          (if (not stop) (loop))))))
         (gaps (let turn ((i 0) (last count) (gaps '()))
                 (if (= i 20)
                     gaps
                     (begin (thread-yield!)
                            (turn (+ i 1) count (cons (- count last) gaps)))))))
    (set! stop #t)
    (thread-join! busy)
    (> (apply min (cdr (reverse gaps))) 150)))

;; Scheme that C calls runs in a run of the VM of its own: each comparator
;; of list-sort, and each eval.  Threads switched inside those runs, with
;; comparators that compute, sleep and wait on a mutex, must each come
;; back in their own run; resumed in another, a thread was lost, and
;; Chibi's own scheduler lost one within seconds.  A lost thread makes
;; its join time out (30 s: only a bound, far above the second it takes),
;; or, when the lost one is this body's own, the file stall until the
;; alarm ends it, which tests/run counts as a failure.
(define (nested-caller k shared)
  (lambda ()
    (let loop ((i 0) (sorted '()))
      (if (= i 40)
          (list k (car sorted) (length sorted))
          (loop (+ i 1)
                (cons (list-sort
                       (lambda (a b)
                         (let spin ((j 0)) (if (< j 30) (spin (+ j 1))))
                         (if (zero? (modulo (+ a b i) 7)) (thread-sleep! 0.001))
                         (mutex-lock! shared)
                         (mutex-unlock! shared)
                         (< a b))
                       (list 5 3 9 1 7 2 8 (+ i 10)))
                      sorted))))))

(define (evaluator k)
  (lambda ()
    (let loop ((i 0) (sum 0))
      (if (= i 40)
          (list k sum)
          (loop (+ i 1)
                (+ sum ((eval `(lambda (x)
                                 (let spin ((j 0))
                                   (if (< j 300) (spin (+ j 1)) (+ x ,k))))
                              (environment '(scheme base)))
                        i)))))))

(test "threads that sort and eval at once all come back"
    '((1 (1 2 3 5 7 8 9 49) 40) (2 (1 2 3 5 7 8 9 49) 40)
      (3 (1 2 3 5 7 8 9 49) 40) (4 (1 2 3 5 7 8 9 49) 40)
      (1 820) (2 860) (3 900))
  (let* ((shared (make-mutex))
         (threads (append (map (lambda (k) (start (nested-caller k shared)))
                               '(1 2 3 4))
                          (map (lambda (k) (start (evaluator k))) '(1 2 3)))))
    (map (lambda (t) (thread-join! t 30 'lost)) threads)))

;; This test's body waits for the mutex first, with a deadline, which puts
;; it first in line; then a thread waits for it inside a comparator.  The
;; unlock wakes the body, which may not run until the comparator's run of
;; the VM returns: the wake must go on to the comparator's thread, or
;; neither ever runs again.
(test "a mutex that wakes a waiter who must wait goes to the next" '(locked (1 2))
  (let* ((m (make-mutex))
         (holder (start (lambda ()
                          (mutex-lock! m)
                          (thread-sleep! 0.2)
                          (mutex-unlock! m))))
         (sorter (start (lambda ()
                          (thread-sleep! 0.05)
                          (list-sort (lambda (a b)
                                       (mutex-lock! m)
                                       (mutex-unlock! m)
                                       (< a b))
                                     '(2 1))))))
    (wait-until-owned m holder)
    (let ((locked (mutex-lock! m 60)))
      (mutex-unlock! m)
      (list (if locked 'locked 'timed-out) (thread-join! sorter)))))

(test "a signal is handled while every thread waits" signal/user1
  (let ((gate (make-mutex))
        (caught #f))
    (set-signal-action! signal/user1
                        (lambda (n) (set! caught n) (mutex-unlock! gate)))
    (start block-forever)
    (mutex-lock! gate)
    (tell-peer #\s)
    (mutex-lock! gate)
    caught))

;; As the REPL's Ctrl-C does: a blocked thread raises at once, inside the
;; call that blocked, and has not taken what it waited for.  Without the
;; wake-up each join below gives up after 60 s instead.
(define (interrupted thunk)
  (let ((t (start (lambda ()
                    (guard (e ((error-object? e) (error-object-message e)))
                      (thunk))))))
    (thread-sleep! 0.1)
    (thread-interrupt! t)
    (thread-join! t 60 'still-blocked)))

(test-group "an interrupt reaches a blocked thread at once"
  (test "in a sleep" "interrupt" (interrupted (lambda () (thread-sleep! 3600))))
  (test "waiting on a condition variable" "interrupt"
    (let ((m (make-mutex)))
      (interrupted (lambda ()
                     (mutex-lock! m)
                     (mutex-unlock! m (make-condition-variable) 3600)))))
  (let ((m (make-mutex)))
    (mutex-lock! m)
    (test "waiting for a mutex" "interrupt"
      (interrupted (lambda () (mutex-lock! m))))
    (test "which it has not taken" #t (eq? (current-thread) (mutex-state m)))
    (mutex-unlock! m))
  (test "joining a thread" "interrupt"
    (interrupted (lambda () (thread-join! (start block-forever)))))
  (test "reading a socket" "interrupt"
    (interrupted (lambda () (block-forever)))))

(test-end)

(kill peer signal/kill)
(waitpid peer 0)
(test-exit)
