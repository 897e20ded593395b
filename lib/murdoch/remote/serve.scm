;;;; Serving calls: the callee's side of the wire.
;;
;; The poller (connection.scm) reads a connection until its first call:
;; the hello, answers to our datagram calls and abandons need no thread.
;; Then the connection gets a reader thread, which runs each apply itself
;; (docs/speed.md); an apply that runs past takeover-seconds has the
;; janitor give the connection a new reader, and the old one ends after it.

;; A connection served; its deadline, set while a frame is half read, lets
;; the janitor end a peer that stalls.
(define-record-type serving
  (make-serving peer host thread in out)
  serving?
  (peer serving-peer)
  (host serving-host)
  (thread serving-thread serving-thread-set!)  ; the reader; #f: the poller
  (in serving-in)
  (out serving-out)
  (fd serving-fd serving-fd-set!)       ; #f for the group
  (frames serving-frames serving-frames-set!) ; read, not yet served
  (greeting serving-greeting serving-greeting-set!) ; after the hello
  (deadline serving-deadline serving-deadline-set!)
  (busy-since serving-busy-since serving-busy-since-set!) ; of an inline apply
  (reading serving-reading serving-reading-set!) ; the reader's (served-call.scm)
  (applying serving-applying serving-applying-set!) ; ((ID . THREAD) ...) handed on
  (read-on serving-read-on serving-read-on-set!)) ; a reader's loop

;; The connections served and the lab's limits on them.
(define-record-type server
  (make-server frame-timeout max-connections max-connections-per-host
               servings lock janitor-mutex janitor-wake janitor-resting?
               last-refusal)
  server?
  (frame-timeout server-frame-timeout)  ; the lab's, read once by start-serving!
  (max-connections server-max-connections)
  (max-connections-per-host server-max-connections-per-host)
  (servings server-servings server-servings-set!)
  (lock server-lock)                    ; over servings, and each serving
  (janitor-mutex server-janitor-mutex)  ; see rest-while-idle
  (janitor-wake server-janitor-wake)
  (janitor-resting? server-janitor-resting? server-janitor-resting?-set!)
  (last-refusal server-last-refusal server-last-refusal-set!)) ; monotonic

;; The node's server part: a process is one address space, which serves
;; on one port.
(define-syntax the-server (syntax-rules () ((_) (node-server *node*))))

(define-syntax janitor-wanted!
  (syntax-rules ()
    ((_) (if (server-janitor-resting? (the-server))
             (begin (lock! (server-janitor-mutex (the-server)))
                    (server-janitor-resting?-set! (the-server) #f)
                    (condition-variable-signal! (server-janitor-wake (the-server)))
                    (unlock! (server-janitor-mutex (the-server))))))))

(define janitor-seconds 0.1)
(define takeover-seconds 0.1)

(define (serve-connection fd peer host)
  (let ((s (new-serving! peer host (open-input-file-descriptor fd #t)
                         (open-output-file-descriptor fd #t))))
    (serving-thread-set! s #f)
    (serving-fd-set! s (port-fileno (serving-in s)))
    ;; The hello, which proves the key, is due within frame-timeout of the
    ;; connect: anyone can connect, and a connection holds a descriptor.
    (serving-deadline-set! s (+ (monotonic-seconds)
                                (server-frame-timeout (the-server))))
    (janitor-wanted!)
    (watch-served! (serving-in s) s take-polled! polled-fault!)))

;; A connection (or the multicast group) that this thread reads.
(define (new-serving! peer host in out)
  (let ((s (make-serving peer host (current-thread) in out)))
    (serving-deadline-set! s #f)
    (serving-busy-since-set! s #f)
    (serving-reading-set! s #f)
    (serving-applying-set! s '())
    (serving-fd-set! s #f)
    (serving-frames-set! s '())
    (serving-greeting-set! s #f)
    (with-lock (server-lock (the-server))
      (lambda ()
        (server-servings-set! (the-server) (cons s (server-servings (the-server))))))
    s))

(define-syntax reader?
  (syntax-rules () ((_ s) (eq? (current-thread) (serving-thread s)))))

;; Runs a reader's loop; the connection ends with it, unless handed on.
(define (read-as-reader s thunk)
  (guard (e (#t (let-go-of-writes! s)
                (log-fault (serving-peer s) e)))
    (thunk))
  (if (reader? s) (end-serving! s)))

;; Once: the janitor and the reader may both end it.  The poller lets go of
;; the descriptor first, as a closed number may be another connection's next.
(define (end-serving! s)
  (when (with-lock (server-lock (the-server))
          (lambda ()
            (and (memq s (server-servings (the-server)))
                 (begin (server-servings-set!
                         (the-server) (remove (lambda (x) (eq? x s))
                                          (server-servings (the-server))))
                        #t))))
    (if (serving-fd s) (unwatch-served! (serving-fd s) #f))
    (guard (e (#t #f)) (close-input-port (serving-in s)))
    (guard (e (#t #f)) (close-output-port (serving-out s)))))

;; The message of s's next frame, checked to be one a caller may send.
(define-syntax open-served
  (syntax-rules () ((_ s bytes) (open-counted s (serving-greeting s) bytes))))

;;; Frames as the poller reads them

;; The frames, eof or fault the poller read from s: hello, answers and
;; abandons are served here; at the first call s goes to a reader thread.
(define (take-polled! s items)
  (cond ((null? items) (await-whole! s))
        ((bytevector? (car items))
         (if (serving-greeting s)
             (take-opened! s (open-served s (car items)) (cdr items))
             (begin (greet! s (open-frame (car items) "hello" 0))
                    (take-polled! s (cdr items)))))
        ;; A peer that connects and leaves at once is probing the port.
        ((eof-object? (car items)) (end-serving! s))
        (else (protocol-fail "netstring" (car items)))))

(define (take-opened! s message rest)
  (if (memq (car message) '(run apply))
      (hand-to-reader! s (cons message rest))
      (begin (serve-notice s (greeting-uid (serving-greeting s)) message)
             (take-polled! s rest))))

(define (await-whole! s)
  (cond ((> (poller-buffered (serving-fd s)) 0) ; positive? is a call
         (if (serving-deadline s)
             #f
             (begin (serving-deadline-set! s (+ (monotonic-seconds)
                                                (server-frame-timeout (the-server))))
                    (janitor-wanted!))))
        ((serving-greeting s) (serving-deadline-set! s #f))))

;; A frame that breaks the protocol, or a wrong hello, ends its connection.
(define (polled-fault! s e)
  (log-fault (serving-peer s) e)
  (end-serving! s))

(define (hand-to-reader! s frames)
  (unwatch-served! (serving-fd s) #t)
  (serving-frames-set! s frames)
  (serving-deadline-set! s #f)
  (let ((t (make-guarded-thread (lambda () (read-as-reader s (serving-read-on s)))
                                'connection)))
    (with-lock (server-lock (the-server)) (lambda () (serving-thread-set! s t)))
    (thread-start! t)))

;; The next message of s for its reader, or an eof object; a frame begun
;; has frame-timeout to come whole.  No let to answer-call (docs/speed.md).
(define-syntax read-served
  (syntax-rules () ((_ s) (opened s (next-served-frame s)))))

(define (opened s x)
  (cond ((pair? x) x)                   ; opened and checked by the poller
        ((bytevector? x) (open-served s x))
        ((eof-object? x) x)
        (else (protocol-fail "netstring" x))))

(define (next-served-frame s)
  (if (pair? (serving-frames s))
      (first-frame! s (serving-frames s))
      (begin
        (await-whole! s)
        (port-wait! (serving-in s) 3600.) ; inexact: no flonum made a wait
        (serving-frames-set! s (poller-frames! (serving-fd s) (max-frame)))
        (next-served-frame s))))

(define (first-frame! s frames)
  (serving-frames-set! s (cdr frames))
  (car frames))

(define (open-counted s g bytes)
  (greeting-count-set! g (+ 1 (greeting-count g)))
  (serving-deadline-set! s #f)
  (check-message (open-frame bytes (greeting-nonce g) (greeting-count g))
                 '(run apply answer abandon) "a call"))

(define (janitor)
  (thread-sleep! janitor-seconds)
  (let ((now (monotonic-seconds)))
    (for-each end-stalled! (serving-where serving-deadline now))
    (for-each take-over! (serving-where serving-busy-since
                                        (- now takeover-seconds))))
  (rest-while-idle)
  (janitor))

(define (serving-where moment time)
  (with-lock (server-lock (the-server))
    (lambda ()
      (filter (lambda (s) (let ((t (moment s))) (and t (< t time))))
              (server-servings (the-server))))))

;; The janitor rests while no frame is half read and no reader applies
;; (docs/speed.md).  It raises its flag before it looks and holds its
;; mutex from the flag to the wait; a reader sets what it begins before it
;; reads the flag: so either the look sees it, or its wake-up finds the
;; janitor waiting.
(define (rest-while-idle)
  (let ((m (server-janitor-mutex (the-server))))
    (lock! m)
    (server-janitor-resting?-set! (the-server) #t)
    (cond ((pair? (serving-where (lambda (s) (or (serving-deadline s)
                                                 (serving-busy-since s)))
                                 +inf.0))
           (server-janitor-resting?-set! (the-server) #f)
           (unlock! m))
          (else (unlock-waiting! m (server-janitor-wake (the-server)))))))

(define (end-stalled! s)
  (log-warn "connection with " (serving-peer s)
            " closed: no whole frame within frame-timeout")
  (if (serving-thread s) (thread-terminate! (serving-thread s)))
  (end-serving! s))

(define (take-over! s)
  (lock! (server-lock (the-server)))
  (when (serving-busy-since s)          ; its apply may just have ended
    (let ((t (make-guarded-thread
              (lambda () (read-as-reader s (serving-read-on s)))
              'connection)))
      (keep-applying! s (reading-call (serving-reading s)))
      (serving-busy-since-set! s #f)
      (serving-thread-set! s t)
      (thread-start! t)))
  (unlock! (server-lock (the-server))))

(define (keep-applying! s c)
  (if c
      (serving-applying-set! s (cons (cons (served-call-id c) (serving-thread s))
                                     (serving-applying s)))))

;;> Run by an apply that runs long, a task's component say: its connection
;;> gets a new reader now, so the caller's next calls do not wait.
(define (hand-over-connection!)
  (lock! (server-lock (the-server)))
  (let ((s (find (lambda (s) (and (eq? (serving-thread s) (current-thread))
                                  (serving-busy-since s)))
                 (server-servings (the-server)))))
    (unlock! (server-lock (the-server)))
    (if s (take-over! s))))

;; The reader's inline apply, marked for the janitor without the lock (only a
;; reader starts one: docs/speed.md); its call listed for abandon-call! once handed on.
(define-syntax inline-apply-begins!
  (syntax-rules ()
    ((_ s) (begin (serving-busy-since-set! s (monotonic-seconds)) (janitor-wanted!)))))

(define-syntax inline-apply-ends!       ; whether still the reader
  (syntax-rules ()
    ((_ s) (begin (lock! (server-lock (the-server))) (apply-ended! s (reader? s))))))

(define (apply-ended! s still)
  (if still
      (serving-busy-since-set! s #f)
      (serving-applying-set! s (without-thread (serving-applying s) (current-thread))))
  (unlock! (server-lock (the-server)))
  (if (abandoned?) (forget-abandoned! (current-thread)))
  still)

;; Not remove (docs/speed.md).
(define (without-thread applying thread)
  (cond ((null? applying) '())
        ((eq? (cdar applying) thread) (without-thread (cdr applying) thread))
        (else (cons (car applying) (without-thread (cdr applying) thread)))))

;;> Lets the call that \var{thread} runs here go from its caller, whose
;;> giving up no longer stops it: a component a new coordinator adopts.
(define (release-call! thread)
  (with-lock (server-lock (the-server))
    (lambda ()
      (for-each (lambda (s)
                  (serving-applying-set! s (without-thread (serving-applying s) thread)))
                (server-servings (the-server))))))

;; The caller of apply id gave up: its thread is marked to stop (code/abandon.scm).
(define (abandon-call! s id)
  (let ((a (with-lock (server-lock (the-server))
             (lambda () (assv id (serving-applying s))))))
    (when a
      (log-note "call " id " from " (serving-peer s) " abandoned by its caller;"
                " it stops at its next remote call or robot command")
      (abandon-thread! (cdr a)))))

(define (peer-name sockaddr)
  (string-append (sockaddr-name sockaddr) ":"
                 (number->string (sockaddr-port sockaddr))))

(define (accept-loop listener addr)
  (let ((fd (accept listener (address-info-address addr)
                    (address-info-address-length addr))))
    (if fd
        (let ((peer (peer-name (address-info-address addr)))
              (host (sockaddr-name (address-info-address addr))))
          (if (room-for? host)
              (serve-connection fd peer host)
              (refuse-connection! fd peer))))
    (accept-loop listener addr)))

;; Whether a connection from host stays under the lab's caps, in all and a
;; host: connections that never say hello could take every descriptor.
(define (room-for? host)
  (with-lock (server-lock (the-server))
    (lambda ()
      (let* ((servings (server-servings (the-server)))
             (from-host (count (lambda (s) (equal? (serving-host s) host))
                               servings)))
        (and (< (length servings) (server-max-connections (the-server)))
             (< from-host (server-max-connections-per-host (the-server))))))))

;; Closes a connection over the caps; the log tells of one a second.
(define (refuse-connection! fd peer)
  (close-port (open-input-file-descriptor fd #t))
  (when (> (monotonic-seconds) (+ (server-last-refusal (the-server)) 1))
    (server-last-refusal-set! (the-server) (monotonic-seconds))
    (log-warn "connection from " peer " refused: over max-connections"
              " or max-connections-per-host")))

;;> Serves calls here under the lab's limits, and starts the janitor.
(define (start-serving!)
  (node-server-set! (this-node)
                    (make-server (setting 'frame-timeout) (setting 'max-connections)
                                 (setting 'max-connections-per-host) '()
                                 (make-mutex 'serving) (make-mutex 'janitor)
                                 (make-condition-variable 'janitor) #f -inf.0))
  (let* ((host (aspace-host (local-aspace)))
         (port (aspace-port (local-aspace)))
         (addr (get-address-info host port)))
    (if (not addr) (error "cannot resolve the interface" host))
    (let ((listener
           (guard (e (#t (error (string-append "cannot listen on " host ":"
                                               (number->string port)
                                               " (is another process there?)"))))
             (make-listener-socket addr))))
      (if (zero? port) (local-aspace-port-set! (socket-port listener)))
      (spawn (lambda () (accept-loop listener addr)) 'accept)
      (spawn janitor 'janitor))))
