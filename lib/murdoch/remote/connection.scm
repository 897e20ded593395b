;;;; Connections to other address spaces: the caller's side of the wire.
;;;; A call goes out on the one connection kept to its target, greeted
;;;; when made; one thread, the poller, reads every connection on the
;;;; scheduler's epoll descriptor and hands each answer to its call by id.

(define-record-type connection
  (make-connection uid in out text write-lock pending own-nonce welcome)
  connection?
  (uid connection-uid)
  (in connection-in)
  (out connection-out)
  (text connection-text)                       ; see write-frame!
  (write-lock connection-write-lock)
  (pending connection-pending)                 ; id -> pending-call
  (own-nonce connection-own-nonce)             ; the callee MACs with it
  (welcome connection-welcome)                 ; a mailbox: #t, or the fault
  (fd connection-fd connection-fd-set!)        ; while the poller watches it
  (received connection-received connection-received-set!)
  (nonce connection-nonce connection-nonce-set!) ; the callee's
  (sent connection-sent connection-sent-set!)
  (flushed connection-flushed connection-flushed-set!) ; sent when last flushed
  (next-id connection-next-id connection-next-id-set!)
  (stage connection-stage connection-stage-set!) ; of the send under the lock
  (open? connection-open? connection-open?-set!))

;;> A call on its way to uid, or uid's answer to a datagram call; its
;;> answer, #f until it comes, is handed in through its gathering.
(define-lean-record-type pending-call
  (make-pending-call uid connection id gathering answer)
  pending-call?
  (uid pending-call-uid)
  (connection pending-call-connection)
  (id pending-call-id)
  (gathering pending-call-gathering)
  (answer pending-call-answer pending-call-answer-set!))

;;> Gives pending call p its answer, unless it has one.
(define (answer-call! p answer)
  (gathering-put! (pending-call-gathering p) p answer
                  pending-call-answer pending-call-answer-set!))

;; The node's connections part: one connection to each peer, made by the first
;; call to it from any thread, and a lock for each uid being connected to, so
;; that a peer that does not answer holds up only the calls to it.
(define-record-type connections
  (make-connections table connecting lock)
  connections?
  (table connections-table)             ; uid -> connection
  (connecting connections-connecting)   ; uid -> mutex
  (lock connections-lock))              ; over both, and the poller's table

(define-syntax the-connections (syntax-rules () ((_) (node-connections *node*))))

;;> Makes the node's connections part, before any call or served connection.
(define (open-connections!)
  (node-connections-set! (this-node)
                         (make-connections (make-hash-table eq?) (make-hash-table eq?)
                                           (make-mutex 'connections))))

;; The open connection to a, made and greeted by the deadline if there is none.
;; No let or or: closures every call to every peer would make (docs/speed.md).
(define (connection-to a deadline)
  (live-or-new (live-connection-to (aspace-uid a)) a deadline))

(define (live-or-new live a deadline)
  (if live live (new-connection-to a (aspace-uid a) deadline)))

(define (new-connection-to a uid deadline)
  (undo-on-raise
   (lambda () (note-unreachable! uid))
   (lambda ()
     (with-lock-by (connecting-lock uid) deadline
       (lambda ()
         (remote-error 'timed-out uid 'connect
                       "another call's connect did not end in time"))
       (lambda ()
         (or (live-connection-to uid)
             (let ((c (connect! a deadline)))
               (with-lock (connections-lock (the-connections))
                 (lambda () (hash-table-set! (connections-table (the-connections)) uid c)))
               c)))))))

;; No wind around the lock: nothing under it raises, and every call comes here.
(define (live-connection-to uid)
  (lock! (connections-lock (the-connections)))
  (open-in (unlocked (connections-lock (the-connections))
                     (hash-table-cell (connections-table (the-connections)) uid #f))))

(define (open-in cell)
  (and cell (connection-open? (cdr cell)) (cdr cell)))

(define (connecting-lock uid)
  (with-lock (connections-lock (the-connections))
    (lambda ()
      (or (hash-table-ref/default (connections-connecting (the-connections)) uid #f)
          (let ((m (make-mutex 'connecting)))
            (hash-table-set! (connections-connecting (the-connections)) uid m)
            m)))))

(define (connect! a deadline)
  (let ((io (open-connection (aspace-host a) (aspace-port a)
                             (seconds-until deadline))))
    (if (string? io)
        (remote-error (if (string-prefix? "no connection within" io)
                          'timed-out
                          'unreachable)
                      (aspace-uid a) 'connect
                      (string-append "cannot connect to " (aspace-host a) ":"
                                     (number->string (aspace-port a)) ": " io)))
    (let* ((nonce (random-hex 16))
           (c (make-connection (aspace-uid a) (car io) (cadr io)
                               (open-output-string) (make-mutex 'connection-write)
                               (make-hash-table eq?) nonce (make-mailbox))))
      (connection-fd-set! c #f)
      (connection-received-set! c 0)
      (connection-nonce-set! c #f)
      (connection-sent-set! c 0)
      (connection-flushed-set! c 0)
      (connection-next-id-set! c 0)
      (connection-stage-set! c 'sent)
      (connection-open?-set! c #t)
      (send-frame! (connection-out c) (connection-text c) "hello" 0
                   (let ((me (local-aspace)))
                     (make-message 'hello (aspace-uid me) (aspace-host me)
                                   (aspace-port me) nonce)))
      (watch! c)
      (let ((greeted (mailbox-take
                      (connection-welcome c) deadline
                      (lambda ()
                        (close-connection! c)
                        (remote-error 'timed-out (aspace-uid a) 'connect
                                      "no welcome")))))
        (if (not (eq? greeted #t))
            (remote-error (if (protocol-fault? greeted) 'protocol 'unreachable)
                          (aspace-uid a) 'connect (fault-message greeted))))
      c)))

;;; The poller

;; Global, one poller's: connections by descriptor, read without a lock (a
;; vector-set! is whole), replaced by a larger one under the connections' lock.
(define *watched* (make-vector 64 #f))
(define *poller-port* #f)               ; on the epoll descriptor

(define (watch! c)
  (connection-fd-set! c (port-fileno (connection-in c)))   ; before the poller sees it
  (watch-port! (connection-in c) c))

;;> Watches the connection served on \var{in}: the poller gives
;;> \scheme{(take s items)} or \scheme{(fault s e)}; answers the descriptor.
(define (watch-served! in s take fault)
  (watch-port! in (make-watcher s take fault)))

;; The poller reads input port in, as entry; answers the descriptor.  The
;; entry is set before epoll watches it, since the poller drops a ready
;; descriptor it does not know, and with it the welcome.
(define (watch-port! in entry)
  (with-lock (connections-lock (the-connections))
    (lambda ()
      (if (not *poller-port*) (start-poller!))
      (let ((fd (port-fileno in)))
        (if (>= fd (vector-length *watched*))
            (set! *watched* (vector-grow *watched* (* 2 (+ fd 1)))))
        (vector-set! *watched* fd entry)
        (poller-watch! in)
        fd))))

;;> The poller stops reading served descriptor \var{fd}: for good, or with
;;> \var{keep?} leaving its buffer to a thread of its own.
(define (unwatch-served! fd keep?)
  (with-lock (connections-lock (the-connections))
    (lambda ()
      (vector-set! *watched* fd #f)
      (if keep? (poller-release! fd) (poller-unwatch! fd)))))

(define-record-type watcher
  (make-watcher serving take fault)
  watcher?
  (serving watcher-serving)
  (take watcher-take)
  (fault watcher-fault))

(define (vector-grow v n)
  (let ((grown (make-vector n #f)))
    (vector-copy! grown 0 v)
    grown))

(define (start-poller!)
  (set! *poller-port* (poller-port))
  (thread-start! (make-logged-thread poll-connections 'poller)))

;; Reads each connection as its bytes come, under one handler (docs/speed.md);
;; a frame that breaks the protocol closes its connection.
(define (poll-connections)
  (let ((current #f))
    (define (take! fd)
      (let ((c (and (< fd (vector-length *watched*)) (vector-ref *watched* fd))))
        (set! current c)
        (cond ((connection? c) (take-frames! c (poller-frames! fd (max-frame))))
              (c ((watcher-take c) (watcher-serving c) (poller-frames! fd (max-frame))))
              (else (poller-unwatch! fd)))))
    (let again ()
      (guard (e (#t (cond ((connection? current) (connection-fault! current e))
                          (current ((watcher-fault current) (watcher-serving current) e)))
                    (again)))
        (let loop ()
          (let ((fds (poller-ready)))
            (if (null? fds)
                (port-wait! *poller-port* 3600.)
                (for-each take! fds)))
          (loop))))))

(define (take-frames! c taken)
  (when (pair? taken)
    (take-frame! c (car taken))
    (take-frames! c (cdr taken))))

;; The welcome, then answers, each handed to the call that waits for it.
(define (take-frame! c x)
  (cond ((bytevector? x)
         (connection-received-set! c (+ 1 (connection-received c)))
         (take-message! c (open-frame x (connection-own-nonce c)
                                      (- (connection-received c) 1))))
        ((not (eof-object? x)) (protocol-fail "netstring" x))
        ((connection-nonce c) (close-connection! c))
        (else (greeted! c x))))

;; No let above (docs/speed.md).
(define (take-message! c message)
  (if (connection-nonce c)
      (deliver-answer! c message)
      (greeted! c message)))

(define (greeted! c w)
  (connection-nonce-set! c (welcome-nonce w (connection-uid c)))
  (mailbox-put! (connection-welcome c) #t))

;; The welcome mailbox gets what was wrong with the welcome: only faults
;; after it are logged, lest the prober's tries of a gone peer fill the log.
(define (connection-fault! c e)
  (if (connection-nonce c)
      (log-fault (connection-uid c) e)
      (mailbox-put! (connection-welcome c) e))
  (close-connection! c))

;; The nonce of w, the welcome from uid.  One from another address space,
;; on the port uid had, would answer in its name: uid would never leave.
(define (welcome-nonce w uid)
  (if (eof-object? w)
      (error "the connection closed before its welcome"))
  (let ((found (message-field (check-message w '(welcome) "a welcome") 'uid)))
    (if (not (eq? found uid))
        (error (string-append "found " (symbol->string found) " at its address")))
    (message-field w 'nonce)))

;; No wind around the lock (nothing under it raises), no match or let.
(define (deliver-answer! c answer)
  (check-message answer '(ack value error) "an answer")
  (lock! (connection-write-lock c))
  (answer-pending! (unlocked (connection-write-lock c)
                             (take-mailbox! (connection-pending c) (message-id answer)))
                   answer))

(define (answer-pending! p answer)
  (if p (answer-call! p answer)))       ; else the caller gave up

;; Close once; waiting calls hear the connection is lost.  Unwatched first.
(define (close-connection! c)
  (let* ((fd #f)
         (waiting
          (with-lock (connection-write-lock c)
            (lambda ()
              (set! fd (connection-fd c))
              (connection-fd-set! c #f)
              (connection-open?-set! c #f)
              (take-all-mailboxes! (connection-pending c))))))
    (when fd
      (with-lock (connections-lock (the-connections))
        (lambda ()
          (vector-set! *watched* fd #f)
          (poller-unwatch! fd)))
      ;; Closed once: its number may be another socket's next.
      (guard (e (#t #f)) (close-input-port (connection-in c)))
      (guard (e (#t #f)) (close-output-port (connection-out c))))
    (for-each (lambda (p) (answer-call! p '(lost))) waiting)))

;;> Sends one call, \var{tail} its text but the id, answered to gathering
;;> g; answers the pending call.
(define (send-call! c tail g)
  (send-pending! c tail (make-pending-call (connection-uid c) c (next-call-id! c) g #f)))

(define (send-pending! c tail p)
  (send-counted! c (spliced-text tail (pending-call-id p)) p)
  p)

;; An id no other call on c has (no wind: nothing under the lock raises).
(define (next-call-id! c)
  (lock! (connection-write-lock c))
  (connection-next-id-set! c (+ 1 (connection-next-id c)))
  (unlocked (connection-write-lock c) (connection-next-id c)))

;; Sends message as c's next frame under c's write lock, p (or #f) in c's
;; table; a count flushes the frames to it.  A failed write or flush closes c
;; to calls, an unsendable message leaves it be; either way p is taken out,
;; the peer noted unreachable.  One wind point, one undo closure, no let.
(define (send-counted! c message p)
  (lock! (connection-write-lock c))
  (connection-stage-set! c 'before)
  (sent-counted! c message p (undo-begun! (lambda () (after-send! c p)))))

(define (sent-counted! c message p here)
  (undo-ended here (write-counted! c message p))
  (after-send! c p))

(define (write-counted! c message p)
  (if (not (connection-open? c))
      (remote-error 'unreachable (connection-uid c) 'send "connection lost"))
  (cond ((exact-integer? message) (flush-to! c message))
        ((string? message) (write-frame-text! c message p))
        (else (write-frame-text! c (frame-text (connection-text c) message) p))))

(define (write-frame-text! c text p)
  (if p (hash-table-set! (connection-pending c) (pending-call-id p) p))
  (connection-sent-set! c (+ 1 (connection-sent c)))
  (connection-stage-set! c 'writing)
  (write-frame! (connection-out c) text (connection-nonce c) (connection-sent c))
  (if (coalesce? c) (connection-stage-set! c 'written) (flush-to! c (connection-sent c))))

;; Whether frames written wait for other senders' (docs/speed.md): while
;; another thread can run, and the peer has more calls than wait here
;; unflushed, or, with calls besides this one, the ends take turns at a CPU.
(define (coalesce? c)
  (and (others-runnable?)
       (few-unflushed? (- (connection-sent c) (connection-flushed c))
                       (hash-table-size (connection-pending c)))))

(define (few-unflushed? unflushed pending)
  (if (< (* 2 unflushed) pending)
      #t
      (and (> pending 1) (cpu-contended?))))

(define (flush-to! c count)
  (when (< (connection-flushed c) count)
    (connection-stage-set! c 'writing)
    (flush-output-port (connection-out c))
    (connection-flushed-set! c (connection-sent c)))
  (connection-stage-set! c 'sent))

(define (after-send! c p)
  (when (not (memq (connection-stage c) '(written sent)))
    (if (eq? (connection-stage c) 'writing) (connection-open?-set! c #f))
    (if p (hash-table-delete! (connection-pending c) (pending-call-id p))))
  (unlock-after-send! c p (connection-stage c) (connection-sent c)))

;; Frames written wait a turn of the others; flushed only grows: read unlocked.
(define (unlock-after-send! c p stage count)
  (unlock! (connection-write-lock c))
  (cond ((eq? stage 'written)
         (thread-yield!)
         (if (< (connection-flushed c) count) (send-counted! c count p)))
        ((eq? stage 'sent))
        (p (note-unreachable! (connection-uid c)))))

;;> Sends a's datagram call id its answer (answer ID KIND VALUE), unacknowledged.
(define (send-datagram-answer! a id kind value)
  (send-counted! (connection-to a (+ (monotonic-seconds) (current-timeout)))
                 (make-message 'answer id kind value) #f))

;; Forgets call id, telling the callee if the connection stands (code/abandon.scm).
(define (give-up-call! c id)
  (with-lock (connection-write-lock c)
    (lambda () (hash-table-delete! (connection-pending c) id)))
  (guard (e (#t #f))                    ; the connection broke: no matter
    (send-counted! c (make-message 'abandon id) #f)))
