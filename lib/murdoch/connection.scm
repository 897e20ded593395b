;;;; Connections to other address spaces: the caller's side of the wire.
;;
;; A call goes out on the one connection this address space keeps to its
;; target, made and greeted (steps 1 and 2 of frame.scm's protocol) when
;; there is none.  The connection's reader thread hands each answer to the
;; mailbox of the call that waits for it.

(define-record-type connection
  (make-connection uid in out text write-lock pending)
  connection?
  (uid connection-uid)
  (in connection-in)
  (out connection-out)
  (text connection-text)                       ; see write-frame!
  (write-lock connection-write-lock)
  (pending connection-pending)                 ; id -> mailbox
  (nonce connection-nonce connection-nonce-set!) ; the callee's
  (sent connection-sent connection-sent-set!)
  (next-id connection-next-id connection-next-id-set!)
  (open? connection-open? connection-open?-set!))

;; The open connections, and a lock for each uid that one thread holds
;; while it connects to that uid: a peer that does not answer holds up the
;; calls to it for their timeout, and no call to another peer.
(define *connections* (make-hash-table eq?))  ; uid -> connection
(define *connecting* (make-hash-table eq?))   ; uid -> mutex
(define *connections-lock* (make-mutex 'connections))

;; The open connection to uid, made (and greeted) if there is none, by
;; the deadline (on the monotonic clock).
(define (connection-to a deadline)
  (let ((uid (aspace-uid a)))
    (or (live-connection-to uid)
        (with-lock-by (connecting-lock uid) deadline
          (lambda ()
            (remote-error 'timed-out uid 'connect "another call's connect did not end in time"))
          (lambda ()
            (or (live-connection-to uid)
                (let ((c (connect! a deadline)))
                  (with-lock *connections-lock*
                    (lambda () (hash-table-set! *connections* uid c)))
                  c)))))))

(define (live-connection-to uid)
  (with-lock *connections-lock*
    (lambda ()
      (let ((c (hash-table-ref/default *connections* uid #f)))
        (and c (connection-open? c) c)))))

(define (connecting-lock uid)
  (with-lock *connections-lock*
    (lambda ()
      (or (hash-table-ref/default *connecting* uid #f)
          (let ((m (make-mutex uid)))
            (hash-table-set! *connecting* uid m)
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
    (let ((c (make-connection (aspace-uid a) (car io) (cadr io)
                              (open-output-string)
                              (make-mutex) (make-hash-table eqv?)))
          (nonce (random-hex 16))
          (welcome (make-mailbox)))
      (connection-nonce-set! c #f)
      (connection-sent-set! c 0)
      (connection-next-id-set! c 0)
      (connection-open?-set! c #t)
      (send-frame! (connection-out c) (connection-text c) "hello" 0
                   (let ((me (local-aspace)))
                     (make-message 'hello (aspace-uid me) (aspace-host me)
                                   (aspace-port me) nonce)))
      (thread-start! (make-thread (lambda () (read-answers c nonce welcome))
                                  'answers))
      (let ((greeted (mailbox-take
                      welcome deadline
                      (lambda ()
                        (close-connection! c)
                        (remote-error 'timed-out (aspace-uid a) 'connect
                                      "no welcome")))))
        (if (not (eq? greeted #t))
            (remote-error (if (protocol-fault? greeted) 'protocol 'unreachable)
                          (aspace-uid a) 'connect (fault-message greeted))))
      c)))

;; The reader of one outgoing connection: the welcome, then answers, each
;; handed to the mailbox of the call that waits for it.  The welcome
;; mailbox gets #t, or what was wrong with the welcome, which the call
;; reports: only faults after the welcome are logged, so that the prober,
;; trying a gone peer every second, does not fill the log.
(define (read-answers c nonce welcome)
  (guard (e (#t (mailbox-put! welcome e)
                (if (connection-nonce c) (log-fault (connection-uid c) e))))
    (let ((w (read-frame (connection-in c) nonce 0)))
      (connection-nonce-set! c (welcome-nonce w (connection-uid c)))
      (mailbox-put! welcome #t)
      (let loop ((count 1))
        (let ((answer (read-frame (connection-in c) nonce count)))
          (if (not (eof-object? answer))
              (begin (deliver-answer! c answer) (loop (+ count 1))))))))
  (close-connection! c))

;; The nonce of w, the welcome from uid.  A welcome from another address
;; space is refused: one that came after uid left, on the port it had,
;; would answer in its name, and uid would never drop out of the lab.
(define (welcome-nonce w uid)
  (if (eof-object? w)
      (error "the connection closed before its welcome"))
  (match (check-message w '(welcome) "a welcome")
    (('welcome found nonce)
     (if (not (eq? found uid))
         (error (string-append "found " (symbol->string found) " at its address")))
     nonce)))

(define (deliver-answer! c answer)
  (let* ((id (match (check-message answer '(ack value error) "an answer")
               ((kind id . value) id)))
         (mb (with-lock (connection-write-lock c)
               (lambda () (take-mailbox! (connection-pending c) id)))))
    (if mb (mailbox-put! mb answer))))   ; else the caller gave up

;; Close once; every call still waiting hears that the connection is lost.
(define (close-connection! c)
  (let ((waiting
         (with-lock (connection-write-lock c)
           (lambda ()
             (and (connection-open? c)
                  (begin
                    (connection-open?-set! c #f)
                    (take-all-mailboxes! (connection-pending c))))))))
    (when waiting
      ;; Closing both ports closes the socket; closing it again could close
      ;; another connection's socket that has taken its number.
      (guard (e (#t #f)) (close-input-port (connection-in c)))
      (guard (e (#t #f)) (close-output-port (connection-out c)))
      (for-each (lambda (mb) (mailbox-put! mb '(lost))) waiting))))

;; Send one call; answers a mailbox that will hold its answer.
(define (send-call! c kind proc-code args-code)
  (with-lock (connection-write-lock c)
    (lambda ()
      (let ((id (+ 1 (connection-next-id c)))
            (mb (make-mailbox)))
        (connection-next-id-set! c id)
        (hash-table-set! (connection-pending c) id mb)
        (send-counted! c (make-message kind id proc-code args-code))
        (cons id mb)))))

;; Sends message as the connection's next frame; the caller holds its
;; write lock.  A frame that fails to go out leaves the connection closed.
(define (send-counted! c message)
  (if (not (connection-open? c))
      (remote-error 'unreachable (connection-uid c) 'send "connection lost"))
  (let ((text (frame-text (connection-text c) message))
        (count (+ 1 (connection-sent c))))
    (connection-sent-set! c count)
    (undo-on-raise
     (lambda () (connection-open?-set! c #f))
     (lambda ()
       (write-frame! (connection-out c) text (connection-nonce c) count)
       (flush-output-port (connection-out c))))))

;;> Sends the answer to call id of a multicast datagram that a, its sender,
;; sent: (answer ID KIND VALUE), which a's reader hands on as it reads it
;; -- no acknowledgement, no worker -- since a waits for it anyway.
(define (send-datagram-answer! a id kind value)
  (let ((c (connection-to a (+ (monotonic-seconds) (current-timeout)))))
    (with-lock (connection-write-lock c)
      (lambda () (send-counted! c (make-message 'answer id kind value))))))

;; Forgets call id, and tells the callee, if the connection still stands,
;; that nobody waits for it (see abandon.scm).
(define (give-up-call! c id)
  (guard (e (#t #f))                    ; the connection broke: no matter
    (with-lock (connection-write-lock c)
      (lambda ()
        (hash-table-delete! (connection-pending c) id)
        (when (connection-open? c)
          (send-counted! c (make-message 'abandon id)))))))
