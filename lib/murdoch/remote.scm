;;;; Address spaces, remote-run! and remote-apply (thesis §3.3.2).
;;
;; An address space is one Chibi process with a uid; the lab file says
;; where each listens.  remote-run! and remote-apply carry a procedure and
;; its arguments to another address space, where the procedure is applied;
;; procedures travel as S-expressions (sendable.scm).
;;
;; The wire protocol.  Each connection is opened by the address space that
;; calls; the callee only answers on it.  Every frame is a netstring whose
;; payload is 64 hex digits of HMAC-SHA256 followed by an S-expression:
;;
;;   MAC = HMAC(key, NONCE ":" COUNT ":" S-EXPRESSION)
;;
;; where NONCE is the one the receiving side chose for this connection and
;; COUNT numbers the frames sent in this direction from 1.  A recorded frame
;; is thus worthless on another connection or at another place in this one.
;;
;;  1. Caller -> callee: (hello UID HOST PORT NONCE), MAC'd with nonce
;;     "hello" and count 0.  HOST and PORT say where the caller listens.
;;  2. Callee -> caller: (welcome UID NONCE), MAC'd with the caller's nonce
;;     and count 0.  From here on each side uses the other's nonce.
;;  3. Caller -> callee, any number, pipelined:
;;       (run ID PROC ARGS)    apply in a worker thread, answer at once
;;       (apply ID PROC ARGS)  apply, answer with the value (see Serving
;;                             calls for which thread applies it)
;;       (answer ID KIND VALUE)  not answered: the answer to call ID of a
;;                             multicast datagram from the callee (multicast.scm)
;;       (abandon ID)          not answered: the caller gave up waiting for
;;                             apply ID; the thread running it stops at its
;;                             next remote call or robot command (abandon.scm)
;;     PROC, ARGS and VALUE are encoded values (sendable.scm); ID is the
;;     caller's, or for an answer the datagram sender's.
;;  4. Callee -> caller, in any order:
;;       (ack ID)  (value ID VALUE)  (error ID MESSAGE)
;;
;; A frame that is not a netstring, fails its MAC, or is not one of these
;; closes its connection after one log line; the address space and its
;; other connections carry on.  Nothing is evaluated before its MAC checks.

;;; Address spaces

(define-record-type aspace
  (make-aspace uid host port)
  aspace?
  (uid aspace-uid)
  (host aspace-host)
  (port aspace-port))

(define *local* #f)                     ; the local aspace, once started
(define *started-at* #f)                ; (current-second) then
(define *lab* #f)
(define *peers* (make-hash-table eq?))  ; uid -> aspace, from lab and hellos
(define *peers-lock* (make-mutex 'peers))

;;> The local address space.
(define (local-aspace)
  (or *local* (error "this process has not joined a lab")))

;;> The (current-second) at which this address space joined its lab.
(define (aspace-started-at) *started-at*)

;;> The uid of the local address space.
(define (local-aspace-uid) (aspace-uid (local-aspace)))

;;> The address space named \var{uid}.
(define (uid->aspace uid)
  (or (with-lock *peers-lock* (lambda () (hash-table-ref/default *peers* uid #f)))
      (error "no address space of this uid is known" uid)))

;;> The uids of every address space known here (the thesis's *uids*).
(define (known-uids)
  (with-lock *peers-lock* (lambda () (hash-table-keys *peers*))))

(define (learn-aspace! a)
  (with-lock *peers-lock*
    (lambda () (hash-table-set! *peers* (aspace-uid a) a))))

;;; Live membership
;;
;; Address spaces come and go.  One that fails to connect, loses its
;; connection or does not answer in time is taken out of the live set, so
;; that publish and request stop waiting on it; a prober tries it again
;; every second and puts it back when it answers.  A newcomer is learned
;; from its hello, so it joins by calling anyone.

(define *unreachable* (make-hash-table eq?))   ; uid -> #t

(define (note-unreachable! uid)
  (if (not (eq? uid (aspace-uid *local*)))
      (with-lock *peers-lock*
        (lambda () (hash-table-set! *unreachable* uid #t)))))

;;> The uids of the address spaces that answer: the broadcast set.
(define (live-uids)
  (with-lock *peers-lock*
    (lambda ()
      (remove (lambda (uid) (hash-table-ref/default *unreachable* uid #f))
              (hash-table-keys *peers*)))))

(define probe-seconds 1)

(define (prober)
  (thread-sleep! probe-seconds)
  (for-each (lambda (uid)
              (guard (e (#t #f))       ; still away
                (parameterize ((remote-timeout probe-seconds))
                  (call (uid->aspace uid) 'apply local-aspace-uid '()))
                (with-lock *peers-lock*
                  (lambda () (hash-table-delete! *unreachable* uid)))))
            (with-lock *peers-lock*
              (lambda () (hash-table-keys *unreachable*))))
  (prober))

;;> Applies \var{thunk} holding the mutex \var{m}, which it frees however
;;> thunk leaves.
(define (with-lock m thunk)
  (dynamic-wind (lambda () (mutex-lock! m)) thunk (lambda () (mutex-unlock! m))))

;; As with-lock, giving up with (too-late) when m is not free by the
;; deadline, on the monotonic clock.
(define (with-lock-by m deadline too-late thunk)
  (if (mutex-lock! m (seconds-until deadline))
      (dynamic-wind (lambda () #f) thunk (lambda () (mutex-unlock! m)))
      (too-late)))

;; Seconds from now to deadline, none if it has passed.
(define (seconds-until deadline)
  (max 0 (- deadline (monotonic-seconds))))

;;> Calls thunk; when it leaves by raising, calls undo on the way out.  A
;; dynamic-wind, not a guard: a guard takes a continuation, which costs
;; Chibi a copy of the stack, 25 KB, each time, and these are on the path
;; of every call.
(define (undo-on-raise undo thunk)
  (let ((done #f))
    (dynamic-wind (lambda () #f)
                  (lambda () (let ((value (thunk))) (set! done #t) value))
                  (lambda () (if (not done) (undo))))))

;;; Settings

(define *default-timeout* 5)

;;> Seconds remote-apply waits for an answer: the global default.
(define (set-remote-timeout! seconds) (set! *default-timeout* seconds))

;;> A per-call override: (parameterize ((remote-timeout 1)) ...).
(define remote-timeout (make-parameter #f))
(sandbox-parameter! remote-timeout)

(define (current-timeout) (or (remote-timeout) *default-timeout*))

;;; Errors

;; The family of errors a remote call raises, one kind for each way it
;; fails; its irritants are the target's uid, the procedure and the
;; message:
;;   timed-out     no answer within the timeout (connecting included)
;;   unreachable   no connection, or it was lost or refused
;;   raised        the procedure raised an error at the callee
;;   protocol      the callee broke the wire protocol (its welcome)
(define remote-error-kinds '(timed-out unreachable raised protocol))

(define (remote-error kind uid what message)
  (raise (make-exception kind
                         (string-append "remote-apply on "
                                        (symbol->string uid) " failed")
                         (list uid what message) #f #f)))

;;> Raised by remote-apply and remote-run! for an error in the target, a
;;> lost connection or a timeout: one of the four kinds below.
(define (remote-error? e)
  (and (exception? e) (memq (exception-kind e) remote-error-kinds) #t))

(define (remote-error-of-kind? kind e)
  (and (exception? e) (eq? (exception-kind e) kind)))

;;> A remote-error for a call that had no answer within its timeout.
(define (remote-timeout-error? e) (remote-error-of-kind? 'timed-out e))

;;> A remote-error for a target that could not be reached, or whose
;;> connection was lost or refused.
(define (remote-unreachable-error? e) (remote-error-of-kind? 'unreachable e))

;;> A remote-error for a procedure that raised an error in the target.
(define (remote-raised-error? e) (remote-error-of-kind? 'raised e))

;;> A remote-error for a target that broke the wire protocol.
(define (remote-protocol-error? e) (remote-error-of-kind? 'protocol e))

(define (remote-error-uid e) (car (exception-irritants e)))
(define (remote-error-message e) (car (cddr (exception-irritants e))))

(define (error-message e)
  (cond
   ((stack-guard-tripped? (current-thread))
    "recursed too deep: its stack neared Chibi's limit, which ends a process")
   ((error-object? e)
    (call-with-output-string
      (lambda (out)
        (write-string (error-object-message e) out)
        (for-each (lambda (x)
                    (write-char #\space out)
                    (write (strip-syntactic-closures x) out))
                  (error-object-irritants e)))))
   (else (call-with-output-string
           (lambda (out) (write-string "raised " out) (write e out))))))

(define (describe-procedure proc)
  (let ((encoded (guard (e (#t #f)) (encode proc *environment* "procedure"))))
    (cond ((and (vector? encoded) (eq? (vector-ref encoded 0) 'murdoch:global))
           (vector-ref encoded 1))
          ((and (vector? encoded) (eq? (vector-ref encoded 0) 'murdoch:closure))
           (vector-ref encoded 1))
          (else proc))))

;;; The environment received code runs in

(define *environment* #f)
(define *decode* #f)

;;> The environment received code runs in: R7RS base, Murdoch's API and the
;;> lab's code files; no file, process, load or eval primitives.
(define (lab-environment) *environment*)

;;; Frames

(define *key* #f)                       ; the lab's, for HMAC
(define *max-frame* 1048576)
(define *max-depth* 4000)

;; Each connection writes its frames' text to a string port of its own,
;; emptied before each frame, so that a write that failed half-way leaves
;; nothing behind (its writer holds the connection's lock): a new string
;; port per frame costs Chibi a 4 KB allocation.
(define (frame-text text-port message)
  (reset-output-string! text-port)
  (write-simple message text-port)
  (let ((text (get-output-string text-port)))
    ;; The receiver would refuse it and close the connection, failing the
    ;; calls on it that had nothing to do with this one.
    (if (> (+ 64 (string-size text)) *max-frame*)
        (error (string-append "the message is larger than the lab's max-frame, "
                              (number->string *max-frame*) " bytes")))
    text))

(define (write-frame! out text nonce count)
  (write-netstring (hmac-sha256-sign *key* text nonce ":" count ":") out))

(define (send-frame! out text-port nonce count message)
  (write-frame! out (frame-text text-port message) nonce count)
  (flush-output-port out))

;;> Raised for a frame that breaks the protocol; the connection closes.
(define-record-type frame-error
  (make-frame-error message)
  frame-error?
  (message frame-error-message))

(define (frame-fail . parts)
  (raise (make-frame-error (apply string-append parts))))

;; The next frame's message, or an eof object when the peer closed.  A
;; bad frame raises (see fault-message), and the connection's one handler
;; closes it: a handler of its own for each frame would cost Chibi a
;; continuation, 25 KB copied, on every message.
(define (read-frame in nonce count)
  (let ((payload (read-netstring in *max-frame*)))
    (if (eof-object? payload)
        payload
        (parse-message
         (authentic-text payload (bytevector-length payload)
                         nonce ":" count ":")))))

;; The text after the MAC in the first end bytes of bytes, once the MAC is
;; that of the parts followed by the text.
(define (authentic-text bytes end . parts)
  (or (apply hmac-sha256-open *key* bytes end parts)
      (frame-fail "bad MAC")))

;; Chibi's own reader, in C: (scheme read) is SRFI 38's, written in
;; Scheme and a hundred times slower.  The C reader recurses without
;; bound and reads datum labels, which make cycles, so the text is first
;; scanned for both (nests-within?): a message may nest twice max-depth,
;; room for its envelope and for a value one level too deep, which
;; decoding then refuses with an error answer; deeper, or with a label,
;; it is a protocol violation.  Text that is no datum raises a read
;; error; our writer puts nothing after the datum.
(define (parse-message text)
  (if (not (nests-within? text (* 2 *max-depth*)))
      (frame-fail "nests deeper than twice max-depth, or has a datum label"))
  (let* ((in (open-input-string text))
         (message (read-datum in)))
    (cond ((eof-object? message) (frame-fail "empty message"))
          ((not (eof-object? (peek-char in))) (frame-fail "trailing data"))
          (else message))))

;; Whether e says that the other side broke the protocol.
(define (protocol-fault? e)
  (or (frame-error? e) (netstring-error? e) (read-error? e)))

;; What was wrong with a frame or datagram that raised e, for the log.
(define (fault-message e)
  (cond ((frame-error? e) (frame-error-message e))
        ((netstring-error? e) (netstring-error-message e))
        ((read-error? e) (string-append "unreadable message: " (error-message e)))
        (else (error-message e))))

;;; Waiting with a deadline

;; A one-shot mailbox: the reader thread puts an answer, the caller takes
;; it or gives up at its deadline.
(define-record-type mailbox
  (%make-mailbox mutex condvar value full?)
  mailbox?
  (mutex mailbox-mutex)
  (condvar mailbox-condvar)
  (value mailbox-value mailbox-value-set!)
  (full? mailbox-full? mailbox-full?-set!))

(define (make-mailbox)
  (%make-mailbox (make-mutex) (make-condition-variable) #f #f))

(define (mailbox-put! mb value)
  (mutex-lock! (mailbox-mutex mb))
  (mailbox-value-set! mb value)
  (mailbox-full?-set! mb #t)
  (condition-variable-broadcast! (mailbox-condvar mb))
  (mutex-unlock! (mailbox-mutex mb)))

;; The mailbox's value, or (timed-out) once the deadline, on the monotonic
;; clock, has passed.  Chibi's SRFI-18 time objects count whole seconds, so
;; each wait is given as the seconds left.
(define (mailbox-take mb deadline timed-out)
  (let loop ()
    (mutex-lock! (mailbox-mutex mb))
    (if (mailbox-full? mb)
        (begin (mutex-unlock! (mailbox-mutex mb))
               (mailbox-value mb))
        (let ((left (seconds-until deadline)))
          (cond
           ((and (positive? left)
                 (mutex-unlock! (mailbox-mutex mb) (mailbox-condvar mb) left))
            (loop))
           (else
            (mutex-unlock! (mailbox-mutex mb))
            (timed-out)))))))

;;; Connections to other address spaces

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
                    `(hello ,(aspace-uid *local*) ,(aspace-host *local*)
                            ,(aspace-port *local*) ,nonce))
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
      (check-welcome w (connection-uid c))
      (connection-nonce-set! c (car (cddr w)))
      (mailbox-put! welcome #t)
      (let loop ((count 1))
        (let ((answer (read-frame (connection-in c) nonce count)))
          (if (not (eof-object? answer))
              (begin (deliver-answer! c answer) (loop (+ count 1))))))))
  (close-connection! c))

;; A welcome from another address space than uid is refused: one that
;; came after uid left, on the port it had, would answer in its name, and
;; uid would never drop out of the lab.
(define (check-welcome w uid)
  (if (eof-object? w)
      (error "the connection closed before its welcome"))
  (if (not (and (list? w) (= (length w) 3) (eq? (car w) 'welcome)
                (symbol? (cadr w)) (string? (car (cddr w)))))
      (frame-fail "expected a welcome"))
  (if (not (eq? (cadr w) uid))
      (error (string-append "found " (symbol->string (cadr w)) " at its address"))))

(define (deliver-answer! c answer)
  (if (not (and (pair? answer) (memq (car answer) '(ack value error))
                (pair? (cdr answer)) (integer? (cadr answer))))
      (frame-fail "not an answer"))
  (let ((mb (with-lock (connection-write-lock c)
              (lambda ()
                (let ((mb (hash-table-ref/default (connection-pending c)
                                                  (cadr answer) #f)))
                  (hash-table-delete! (connection-pending c) (cadr answer))
                  mb)))))
    (if mb (mailbox-put! mb answer))))   ; else the caller gave up

;; Close once; every call still waiting hears that the connection is lost.
(define (close-connection! c)
  (let ((waiting
         (with-lock (connection-write-lock c)
           (lambda ()
             (and (connection-open? c)
                  (begin
                    (connection-open?-set! c #f)
                    (let ((mbs (hash-table-values (connection-pending c))))
                      (for-each (lambda (id)
                                  (hash-table-delete! (connection-pending c) id))
                                (hash-table-keys (connection-pending c)))
                      mbs)))))))
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
        (send-counted! c (list kind id proc-code args-code))
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

;; Sends the answer to call id of a multicast datagram that a, its sender,
;; sent: (answer ID KIND VALUE), which a's reader hands on as it reads it
;; -- no acknowledgement, no worker -- since a waits for it anyway.
(define (send-multicast-answer! a id kind value)
  (let ((c (connection-to a (+ (monotonic-seconds) (current-timeout)))))
    (with-lock (connection-write-lock c)
      (lambda () (send-counted! c (list 'answer id kind value))))))

;; Forgets call id, and tells the callee, if the connection still stands,
;; that nobody waits for it (see abandon.scm).
(define (give-up-call! c id)
  (guard (e (#t #f))                    ; the connection broke: no matter
    (with-lock (connection-write-lock c)
      (lambda ()
        (hash-table-delete! (connection-pending c) id)
        (when (connection-open? c)
          (send-counted! c (list 'abandon id)))))))

;;; remote-run! and remote-apply

(define (call a kind proc args)
  (check-not-abandoned (if (eq? kind 'run) "remote-run!" "remote-apply"))
  (let* ((seconds (current-timeout))
         (proc-code (encode proc *environment* "the procedure"))
         (args-code (encode-arguments args))
         (deadline (+ (monotonic-seconds) seconds)))
    (finish-call (start-call a kind proc-code args-code deadline)
                 deadline seconds proc)))

;; A call on its way: where it went, and the mailbox its answer will reach.
(define-record-type pending-call
  (make-pending-call uid connection id mailbox)
  pending-call?
  (uid pending-call-uid)
  (connection pending-call-connection)
  (id pending-call-id)
  (mailbox pending-call-mailbox))

(define (start-call a kind proc-code args-code deadline)
  (undo-on-raise
   (lambda () (note-unreachable! (aspace-uid a)))
   (lambda ()
     (let* ((c (connection-to a deadline))
            (sent (send-call! c kind proc-code args-code)))
       (make-pending-call (aspace-uid a) c (car sent) (cdr sent))))))

;; The answer to a pending call, by the deadline (on the monotonic
;; clock), which is \var{seconds} after the call began: the value, or a
;; remote-error.
(define (finish-call p deadline seconds proc)
  (await-answer (pending-call-uid p) (pending-call-mailbox p) deadline seconds
                proc
                (lambda ()
                  (give-up-call! (pending-call-connection p) (pending-call-id p)))))

;; The answer that uid puts in mailbox mb to a call of proc, by the
;; deadline: the value, or a remote-error.  (forget) runs when none came,
;; by the deadline or because the wait was interrupted (Ctrl-C).
;; Answers are (ack ID), (value ID VALUE), (error ID MESSAGE) or (lost).
(define (await-answer uid mb deadline seconds proc forget)
  (let ((answer (undo-on-raise
                 forget
                 (lambda ()
                   (mailbox-take mb deadline
                                 (lambda () (timed-out uid proc seconds)))))))
    (case (car answer)
      ((ack) #t)
      ((value) (*decode* (car (cddr answer))))
      ((error) (remote-error 'raised uid (describe-procedure proc)
                             (car (cddr answer))))
      (else (note-unreachable! uid)
            (remote-error 'unreachable uid (describe-procedure proc)
                          "connection lost")))))

;; The call of proc to uid has had no answer within seconds.
(define (timed-out uid proc seconds)
  (note-unreachable! uid)
  (remote-error 'timed-out uid (describe-procedure proc)
                (string-append "no answer within " (number->string seconds) " s")))

;;> Applies \var{proc} to \var{args} in each address space of
;;> \var{aspaces} at once, and answers, in their order, (uid #t value) for
;;> each that answered and (uid #f message) for each that failed or did not
;;> answer within (remote-timeout) seconds.  The procedure is encoded once,
;;> and every call is sent before the first answer is awaited, so the time
;;> taken is about that of the slowest answer, not their sum.
(define (remote-apply-all aspaces proc . args)
  (call-all aspaces 'apply proc args))

;;> As remote-apply-all, with remote-run!: the values are #t.
(define (remote-run-all! aspaces proc . args)
  (call-all aspaces 'run proc args))

;;> remote-apply-all to every live address space (here too): by one
;;> multicast datagram when the lab's delivery is multicast and the message
;;> fits, else to each in turn.
(define (broadcast-apply proc . args) (broadcast 'apply proc args))

;;> remote-run-all! to every live address space, as broadcast-apply.
(define (broadcast-run! proc . args) (broadcast 'run proc args))

(define (broadcast kind proc args)
  (check-not-abandoned (if (eq? kind 'run) "broadcast-run!" "broadcast-apply"))
  (let ((seconds (current-timeout))
        (proc-code (encode proc *environment* "the procedure"))
        (args-code (encode-arguments args)))
    (or (multicast-call-all kind proc-code args-code proc args seconds)
        (send-all (map uid->aspace (live-uids)) kind proc args
                  proc-code args-code seconds))))

(define (call-all aspaces kind proc args)
  (let ((who (if (eq? kind 'run) "remote-run-all!" "remote-apply-all")))
    (check-not-abandoned who)
    (for-each (lambda (a) (check-aspace who a)) aspaces))
  (send-all aspaces kind proc args
            (encode proc *environment* "the procedure")
            (encode-arguments args)
            (current-timeout)))

(define (send-all aspaces kind proc args proc-code args-code seconds)
  (let* ((deadline (+ (monotonic-seconds) seconds))
         (started
          (capture-each aspace-uid
                        (lambda (a)
                          (list (aspace-uid a) #t
                                (if (local? a)
                                    (local-call kind proc args)
                                    (start-call a kind proc-code args-code
                                                deadline))))
                        aspaces)))
    (capture-each car
                  (lambda (s)
                    (if (and (cadr s) (pending-call? (car (cddr s))))
                        (list (car s) #t
                              (finish-call (car (cddr s)) deadline seconds proc))
                        s))
                  started)))

(define (local-call kind proc args)
  (if (eq? kind 'run)
      (begin (run-in-worker (lambda () (apply proc args))) #t)
      (apply-here (local-aspace-uid) proc args)))

(define (capture uid thunk)
  (guard (e (#t (failure-entry uid e)))
    (list uid #t (thunk))))

(define (failure-entry uid e)
  (list uid #f (if (remote-error? e) (remote-error-message e) (error-message e))))

;; (map entry items), where (entry item) answers (uid #t value); an item
;; whose entry raised gives (uid #f message), uid being (uid-of item).
;; The handler is entered once, and again after each failure only: one
;; per item would cost a continuation each (see undo-on-raise).
(define (capture-each uid-of entry items)
  (let ((done '()) (rest items))
    (let run ()
      (guard (e (#t (set! done (cons (failure-entry (uid-of (car rest)) e) done))
                    (set! rest (cdr rest))
                    (run)))
        (let loop ()
          (when (pair? rest)
            (set! done (cons (entry (car rest)) done))
            (set! rest (cdr rest))
            (loop)))))
    (reverse done)))

(define (encode-arguments args)
  (let loop ((args args) (i 1) (acc '()))
    (if (null? args)
        (reverse acc)
        (loop (cdr args) (+ i 1)
              ;; Named only for an error: number->string costs Chibi a
              ;; string port, 4 KB, and this is every argument of every call.
              (cons (encode (car args) *environment*
                            (lambda () (string-append "argument "
                                                      (number->string i))))
                    acc)))))

(define (local? a) (eq? (aspace-uid a) (aspace-uid (local-aspace))))

;; A uid where an address space belongs is the usual slip at the REPL.
(define (check-aspace who a)
  (if (not (aspace? a))
      (error (string-append who ": not an address space;"
                            " (uid->aspace UID) gives one")
             a)))

(define (apply-here uid proc args)
  (guard (e ((remote-error? e) (raise e))
            (#t (remote-error 'raised uid (describe-procedure proc)
                              (error-message e))))
    (apply proc args)))

;;> Applies \var{proc} to \var{args} in a new thread of address space
;;> \var{a}; returns #t once \var{a} has acknowledged.  The result is
;;> discarded.
(define (remote-run! a proc . args)
  (check-aspace "remote-run!" a)
  (if (local? a)
      (local-call 'run proc args)
      (call a 'run proc args)))

;;> Applies \var{proc} to \var{args} in address space \var{a} and returns
;;> the result.  Raises a remote-error naming \var{a}, the procedure and
;;> the message when the application raised, the connection broke, or no
;;> answer came within (remote-timeout) seconds, counted from the call:
;;> connecting and greeting, when there is no connection yet, count too.
(define (remote-apply a proc . args)
  (check-aspace "remote-apply" a)
  (if (local? a)
      (local-call 'apply proc args)
      (call a 'apply proc args)))

(define (spawn thunk name)
  (thread-start! (make-guarded-thread (lambda () (run-logged thunk name)) name)))

(define (run-logged thunk name)
  (guard (e (#t (log-warn name ": " (error-message e))))
    (thunk)))

;;; Workers

;; A remote-run!'s procedure runs in a thread of its own, since its caller
;; does not wait for it (an apply runs in the thread that read it: see
;; Serving calls).  Making a thread costs Chibi more than the rest of a
;; call, so a thread that is done waits a while for the next procedure to
;; run instead of ending.
(define *idle-workers* '())             ; mailboxes of waiting workers
(define *workers-lock* (make-mutex 'workers))
(define worker-idle-seconds 10)

;; Runs thunk in a worker; if it raises, the log says so.
(define (run-in-worker thunk)
  (let ((idle (with-lock *workers-lock*
                (lambda ()
                  (and (pair? *idle-workers*)
                       (let ((mb (car *idle-workers*)))
                         (set! *idle-workers* (cdr *idle-workers*))
                         mb))))))
    (if idle
        (mailbox-put! idle thunk)
        (spawn (lambda () (work thunk)) 'worker))))

;; One handler for the worker's whole life, entered again only after a job
;; raised: a handler per job would cost a continuation each (see
;; undo-on-raise).
(define (work job)
  (let serve ((job job))
    (guard (e (#t (log-warn "worker: " (error-message e))
                  (let ((next (next-job)))
                    (if next (serve next)))))
      (let loop ((job job))
        (job)
        (let ((next (next-job)))
          (if next (loop next)))))))

;; The next job for this worker, or #f when none came within
;; worker-idle-seconds.
(define (next-job)
  (let ((mb (make-mailbox)))
    (with-lock *workers-lock*
      (lambda () (set! *idle-workers* (cons mb *idle-workers*))))
    (or (mailbox-take mb (+ (monotonic-seconds) worker-idle-seconds)
                      (lambda () #f))
        ;; Timed out; but a caller may have taken this worker meanwhile, in
        ;; which case its procedure is on the way.
        (and (not (with-lock *workers-lock*
                    (lambda ()
                      (and (memq mb *idle-workers*)
                           (begin (set! *idle-workers*
                                        (delete mb *idle-workers* eq?))
                                  #t)))))
             ;; The job is on its way; an hour is only a bound.
             (mailbox-take mb (+ (monotonic-seconds) 3600) (lambda () #f))))))

;;; Serving calls
;;
;; Each connection has one reader thread, and the reader runs an apply
;; itself: handing it to a worker cost a thread switch, about a seventh of
;; a receiver's CPU a request.  So that a long apply holds up the calls
;; behind it on its connection for takeover-seconds at most, the janitor
;; then gives the connection a new reader; the old one answers its call
;; and ends.

;; A connection being served.  Its deadline is set while a frame is half
;; read: a peer that stalls mid-frame would otherwise hold a thread and a
;; socket for ever, so the janitor ends it when the deadline passes.
(define-record-type serving
  (make-serving peer host thread in out)
  serving?
  (peer serving-peer)
  (host serving-host)
  (thread serving-thread serving-thread-set!)  ; the reader
  (in serving-in)
  (out serving-out)
  (deadline serving-deadline serving-deadline-set!)
  (busy-since serving-busy-since serving-busy-since-set!) ; of an inline apply
  (applying serving-applying serving-applying-set!) ; ((ID . THREAD) ...)
  (read-on serving-read-on serving-read-on-set!)) ; a reader's loop

(define *serving* '())
(define *serving-lock* (make-mutex 'serving))
(define *frame-timeout* 5)
(define *max-connections* 256)
(define *max-connections-per-host* 64)
(define janitor-seconds 0.1)
(define takeover-seconds 0.1)

(define (serve-connection fd peer host)
  (let ((s (new-serving! peer host (open-input-file-descriptor fd #t)
                         (open-output-file-descriptor fd #t))))
    ;; The hello, which proves the key, is due within frame-timeout of the
    ;; connect: anyone can connect, and an idle connection holds a
    ;; descriptor.
    (serving-deadline-set! s (+ (monotonic-seconds) *frame-timeout*))
    (janitor-wanted!)
    (read-as-reader s (lambda ()
                        (let ((hello (read-served-frame s "hello" 0)))
                          ;; A peer that connects and leaves at once is
                          ;; probing the port.
                          (if (not (eof-object? hello))
                              (serve-calls s hello)))))))

;; A connection (or the multicast group: no ports, no host) that this
;; thread reads, among those the janitor watches.
(define (new-serving! peer host in out)
  (let ((s (make-serving peer host (current-thread) in out)))
    (serving-deadline-set! s #f)
    (serving-busy-since-set! s #f)
    (serving-applying-set! s '())
    (with-lock *serving-lock* (lambda () (set! *serving* (cons s *serving*))))
    s))

;; Runs a reader's loop; the connection ends with it, unless the janitor
;; has given it a new reader meanwhile.
(define (read-as-reader s thunk)
  (guard (e (#t (log-fault (serving-peer s) e)))
    (thunk))
  (if (reader? s) (end-serving! s)))

(define (reader? s) (eq? (current-thread) (serving-thread s)))

(define (end-serving! s)
  (with-lock *serving-lock*
    (lambda () (set! *serving* (remove (lambda (x) (eq? x s)) *serving*))))
  (guard (e (#t #f)) (close-input-port (serving-in s)))
  (guard (e (#t #f)) (close-output-port (serving-out s))))

;; Waits as long as need be for a frame to begin, then gives it
;; *frame-timeout* seconds to arrive whole: less when a deadline is
;; already set (the hello's).
(define (read-served-frame s nonce count)
  (if (eof-object? (peek-u8 (serving-in s)))
      (eof-object)
      (begin
        (serving-deadline-set! s (or (serving-deadline s)
                                     (+ (monotonic-seconds) *frame-timeout*)))
        (janitor-wanted!)
        (let ((message (read-frame (serving-in s) nonce count)))
          (serving-deadline-set! s #f)
          message))))

(define (janitor)
  (thread-sleep! janitor-seconds)
  (let ((now (monotonic-seconds)))
    (for-each end-stalled! (serving-where serving-deadline now))
    (for-each take-over! (serving-where serving-busy-since
                                        (- now takeover-seconds))))
  (rest-while-idle)
  (janitor))

;; The connections whose (moment s) is before time.
(define (serving-where moment time)
  (with-lock *serving-lock*
    (lambda ()
      (filter (lambda (s) (let ((t (moment s))) (and t (< t time))))
              *serving*))))

;; The janitor rests while no frame is half read and no apply runs in a
;; reader: looking ten times a second cost an idle lab of 64 a twelfth of
;; a core.  A reader that begins either wakes it (janitor-wanted!).  The
;; janitor raises its flag before it looks and holds its mutex from the
;; flag to the wait; a reader sets what it begins before it reads the flag.
;; So either the look sees what the reader began, or the reader sees the
;; flag and its wake-up finds the janitor waiting.
(define *janitor-resting* #f)
(define *janitor-mutex* (make-mutex 'janitor))
(define *janitor-wake* (make-condition-variable 'janitor))

(define (rest-while-idle)
  (mutex-lock! *janitor-mutex*)
  (set! *janitor-resting* #t)
  (cond ((pair? (serving-where (lambda (s) (or (serving-deadline s)
                                               (serving-busy-since s)))
                               +inf.0))
         (set! *janitor-resting* #f)
         (mutex-unlock! *janitor-mutex*))
        (else (mutex-unlock! *janitor-mutex* *janitor-wake*))))

(define (janitor-wanted!)
  (when *janitor-resting*
    (mutex-lock! *janitor-mutex*)
    (set! *janitor-resting* #f)
    (condition-variable-signal! *janitor-wake*)
    (mutex-unlock! *janitor-mutex*)))

(define (end-stalled! s)
  (log-warn "connection with " (serving-peer s)
            " closed: no whole frame within frame-timeout")
  (thread-terminate! (serving-thread s))
  (end-serving! s))

(define (take-over! s)
  (mutex-lock! *serving-lock*)
  (when (serving-busy-since s)          ; its apply may just have ended
    (let ((t (make-guarded-thread
              (lambda () (read-as-reader s (serving-read-on s)))
              'connection)))
      (serving-busy-since-set! s #f)
      (serving-thread-set! s t)
      (thread-start! t)))
  (mutex-unlock! *serving-lock*))

;; Marks the start and the end of the reader's inline apply of call id;
;; ending answers whether this thread is still the reader.  Until it ends,
;; the thread is found by id when its caller gives up.
(define (inline-apply-begins! s id)
  (mutex-lock! *serving-lock*)
  (serving-applying-set! s (cons (cons id (current-thread))
                                 (serving-applying s)))
  (serving-busy-since-set! s (monotonic-seconds))
  (mutex-unlock! *serving-lock*)
  (janitor-wanted!))

(define (inline-apply-ends! s)
  (mutex-lock! *serving-lock*)
  (let ((still (reader? s)))
    (serving-applying-set! s (remove (lambda (a) (eq? (cdr a) (current-thread)))
                                     (serving-applying s)))
    (if still (serving-busy-since-set! s #f))
    (mutex-unlock! *serving-lock*)
    (if (abandoned?) (forget-abandoned! (current-thread)))
    still))

;; The caller of apply id gave up on it: its thread is marked, to stop
;; where it next calls out (abandon.scm).  An apply already done is let be.
(define (abandon-call! s id)
  (let ((a (with-lock *serving-lock* (lambda () (assv id (serving-applying s))))))
    (when a
      (log-note "call " id " from " (serving-peer s) " abandoned by its caller;"
                " it stops at its next remote call or robot command")
      (abandon-thread! (cdr a)))))

;; Runs (read-on call) while this thread is s's reader, under one handler
;; for the thread's life: a handler per call would cost a continuation
;; each (see undo-on-raise).  The car of call says which call the thread
;; is running, if any; an error in it is answered by (answer-error call
;; e), any other by (other-failure e), which may raise to end the reader.
(define (read-calls s read-on answer-error other-failure)
  (let ((call (list #f)))
    (let again ()
      (guard (e ((car call)
                 => (lambda (c)
                      (set-car! call #f)
                      (let ((still (inline-apply-ends! s)))
                        (answer-error c e)
                        (if still (again)))))
                (#t (other-failure e)
                    (if (reader? s) (again))))
        (read-on call)))))

;; Runs a call that s's reader has read; (reply KIND VALUE) answers it.
;; Until the answer is made the car of call is marker, for read-calls to
;; answer an error with.  A run is acknowledged once its procedure is decoded, so that one
;; that cannot be is reported to its caller, and runs in a worker; an apply
;; runs here, until the janitor gives s a new reader, and its value goes
;; back.
(define (serve-call s call marker kind proc-code args-code reply)
  (set-car! call marker)
  (if (eq? kind 'run)
      (let ((thunk (decode-call proc-code args-code)))
        (set-car! call #f)
        (reply 'ack #t)
        (run-in-worker thunk))
      (begin
        (inline-apply-begins! s marker)
        ;; Answered while the call is marked: a value that cannot go back
        ;; (too large, say) is answered with the error instead.
        (reply 'value (encoded-result proc-code args-code))
        (set-car! call #f)
        (inline-apply-ends! s))))

(define (serve-calls s hello)
  (let* ((caller-nonce (greet! hello))
         (nonce (random-hex 16))
         (out (serving-out s))
         (text (open-output-string))
         (write-lock (make-mutex))
         (sent 0)
         (count 0))
    ;; The reader's own answers wait in the port's buffer until it has
    ;; read every call that has arrived: a burst of calls is answered in
    ;; one write.  Answers from former readers go at once.
    (define (answer! message)
      (with-lock write-lock
        (lambda ()
          (let ((frame (frame-text text message)))
            (set! sent (+ sent 1))
            ;; A caller that left makes this raise, and the connection end.
            (write-frame! out frame caller-nonce sent))
          (if (not (reader? s)) (flush-output-port out)))))
    (define (flush-if-idle!)
      (if (zero? (buffered-byte-count (serving-in s)))
          (with-lock write-lock (lambda () (flush-output-port out)))))
    ;; Serves frames while this thread is the reader; see read-calls.
    (define (read-on call)
      (let ((message (read-served-frame s nonce (+ count 1))))
        (unless (eof-object? message)
          (set! count (+ count 1))
          (case (and (pair? message) (car message))
            ((answer) (take-multicast-answer! (list-ref hello 1) message))
            ((abandon) (take-abandon! s message))
            (else (serve-frame s call message answer!)))
          (flush-if-idle!)
          (if (reader? s) (read-on call)))))
    (define (serve)
      (read-calls s read-on
                  (lambda (id e)
                    (answer! `(error ,id ,(error-message e)))
                    (flush-if-idle!))
                  raise))
    (send-frame! out text caller-nonce 0 `(welcome ,(aspace-uid *local*) ,nonce))
    (serving-read-on-set! s serve)
    (serve)))

;; Check a hello and learn where its sender listens; answers its nonce.
(define (greet! hello)
  (if (not (and (list? hello) (= (length hello) 5) (eq? (car hello) 'hello)
                (symbol? (list-ref hello 1)) (string? (list-ref hello 2))
                (exact-integer? (list-ref hello 3))
                (string? (list-ref hello 4))))
      (frame-fail "expected a hello"))
  (learn-aspace! (make-aspace (list-ref hello 1) (list-ref hello 2)
                              (list-ref hello 3)))
  (list-ref hello 4))

(define (take-abandon! s message)
  (if (not (and (list? message) (= (length message) 2)
                (exact-integer? (cadr message))))
      (frame-fail "expected (abandon ID)"))
  (abandon-call! s (cadr message)))

(define (serve-frame s call message answer!)
  (if (not (and (list? message) (= (length message) 4)
                (memq (car message) '(run apply))
                (exact-integer? (cadr message))
                (list? (list-ref message 3))))
      (frame-fail "expected a call"))
  (let ((id (cadr message)))
    (serve-call s call id (car message) (list-ref message 2) (list-ref message 3)
                (lambda (kind value)
                  (answer! (if (eq? kind 'ack) `(ack ,id) `(value ,id ,value)))))))

;; The application a call asks for, as a thunk that runs it in the sandbox.
(define (decode-call proc-code args-code)
  (let ((proc (*decode* proc-code))
        (args (*decode* args-code)))
    (if (not (procedure? proc))
        (error "not a procedure" proc))
    (lambda () (call-in-sandbox (lambda () (apply proc args))))))

;; What the application a call asks for answers, encoded to go back.
(define (encoded-result proc-code args-code)
  (encode ((decode-call proc-code args-code)) *environment* "the result"))

(define (peer-name sockaddr)
  (string-append (sockaddr-name sockaddr) ":"
                 (number->string (sockaddr-port sockaddr))))

(define (log-fault peer e)
  (log-warn "connection with " peer " closed: " (fault-message e)))

(define (accept-loop listener)
  (let ((addr (get-address-info (aspace-host *local*) (aspace-port *local*))))
  (let loop ()
    (let ((fd (accept listener (address-info-address addr)
                      (address-info-address-length addr))))
      (if fd
          (let ((peer (peer-name (address-info-address addr)))
                (host (sockaddr-name (address-info-address addr))))
            (if (room-for? host)
                (spawn (lambda () (serve-connection fd peer host)) 'connection)
                (refuse-connection! fd peer))))
      (loop)))))

;; Whether a connection from host stays under the lab's caps, in all and
;; from one host: past them, connections that never say hello could take
;; every descriptor the process has.
(define (room-for? host)
  (with-lock *serving-lock*
    (lambda ()
      (let ((from-host (count (lambda (s) (equal? (serving-host s) host))
                              *serving*)))
        (and (< (length *serving*) *max-connections*)
             (< from-host *max-connections-per-host*))))))

(define *last-refusal* -inf.0)

;; Closes a connection over the caps; the log tells of one a second.
(define (refuse-connection! fd peer)
  (close-port (open-input-file-descriptor fd #t))
  (when (> (monotonic-seconds) (+ *last-refusal* 1))
    (set! *last-refusal* (monotonic-seconds))
    (log-warn "connection from " peer " refused: over max-connections"
              " or max-connections-per-host")))

;;; Proxies

(define *proxies* (make-hash-table eqv?))        ; id -> procedure
(define *proxy-stubs* (make-hash-table equal?))  ; (uid . id) -> proxy
(define *proxies-lock* (make-mutex 'proxies))
(define *next-proxy-id* 0)

;;> Returns a proxy for \var{proc}: a procedure that, applied in any address
;;> space, applies \var{proc} in this one and returns its result.
(define (encap proc)
  (with-lock *proxies-lock*
    (lambda ()
      (set! *next-proxy-id* (+ *next-proxy-id* 1))
      (hash-table-set! *proxies* *next-proxy-id* proc)
      (proxy-stub (local-aspace-uid) *next-proxy-id*))))

;;> Forgets \var{proxy} here: where it was made, the procedure behind it,
;;> so that applying it afterwards raises an error; elsewhere, only this
;;> address space's copy of it, which a later message may bring back.
(define (release-proxy! proxy)
  (let ((ref (proxy-procedure-ref proxy)))
    (with-lock *proxies-lock*
      (lambda ()
        (if (eq? (proxy-ref-uid ref) (local-aspace-uid))
            (hash-table-delete! *proxies* (proxy-ref-id ref)))
        (hash-table-delete! *proxy-stubs*
                            (cons (proxy-ref-uid ref) (proxy-ref-id ref)))))))

;; The one proxy procedure this address space has for (uid . id), so that
;; a proxy sent back and forth stays the same proxy.  Caller holds the lock.
(define (proxy-stub uid id)
  (let ((key (cons uid id)))
    (or (hash-table-ref/default *proxy-stubs* key #f)
        (let ((stub (make-proxy-procedure (make-proxy-ref uid id) apply-proxy)))
          (hash-table-set! *proxy-stubs* key stub)
          stub))))

(define (decode-proxy uid id)
  (with-lock *proxies-lock* (lambda () (proxy-stub uid id))))

(define (apply-proxy ref args)
  (let ((uid (proxy-ref-uid ref)))
    (if (eq? uid (local-aspace-uid))
        (let ((proc (with-lock *proxies-lock*
                      (lambda ()
                        (hash-table-ref/default *proxies* (proxy-ref-id ref)
                                                #f)))))
          (if (not proc)
              (error "this proxy no longer exists" uid (proxy-ref-id ref)))
          (apply proc args))
        (apply remote-apply (uid->aspace uid)
               (decode-proxy uid (proxy-ref-id ref)) args))))

;;; Starting an address space

(define *listener* #f)

;;> Makes this process the address space \var{uid} of \var{lab} (a lab
;;> record, see read-lab), with \var{environment} as the environment that
;;> received code runs in, and starts answering calls.  \var{port} may
;;> override the lab's port for uid.
(define (start-aspace! lab uid environment . port)
  (let ((entry (lab-aspace-by-uid lab uid)))
    (set! *lab* lab)
    (set! *started-at* (current-second))
    (set! *local* (make-aspace uid
                               (if entry (lab-aspace-host entry)
                                   (lab-setting lab 'interface))
                               (cond ((pair? port) (car port))
                                     (entry (lab-aspace-port entry))
                                     (else (error "not in the lab" uid)))))
    (set-log-name! (string-append "murdoch " (symbol->string uid)))
    (set! *environment* environment)
    (set! *decode* (make-decoder environment decode-proxy))
    (set! *key* (lab-key lab))
    (set! *max-frame* (lab-setting lab 'max-frame))
    (set! *max-depth* (lab-setting lab 'max-depth))
    (set-value-limits! *max-depth* (quotient *max-frame* 2))
    (set! *default-timeout* (lab-setting lab 'timeout))
    (set! *frame-timeout* (lab-setting lab 'frame-timeout))
    (set! *max-connections* (lab-setting lab 'max-connections))
    (set! *max-connections-per-host* (lab-setting lab 'max-connections-per-host))
    (set-sandbox-ports! (current-output-port) (current-error-port))
    (for-each (lambda (a)
                (learn-aspace! (make-aspace (lab-aspace-uid a)
                                            (lab-aspace-host a)
                                            (lab-aspace-port a))))
              (lab-aspaces lab))
    (learn-aspace! *local*)
    (set! *listener* (listen-on (aspace-host *local*) (aspace-port *local*)))
    (spawn (lambda () (accept-loop *listener*)) 'accept)
    (spawn janitor 'janitor)
    (spawn prober 'prober)
    (start-multicast! lab)
    *local*))

(define (listen-on host port)
  (let ((addr (get-address-info host port)))
    (if (not addr) (error "cannot resolve the interface" host))
    (guard (e (#t (error (string-append "cannot listen on " host ":"
                                        (number->string port)
                                        " (is another process there?)"))))
      (make-listener-socket addr))))

;;> The lab this address space belongs to.
(define (current-lab) (or *lab* (error "this process has not joined a lab")))

;;; From aux.scm

;;> Evaluates \var{var} in the address space \var{uid}.
(define-syntax var-ref
  (syntax-rules ()
    ((var-ref uid var)
     (remote-apply (uid->aspace uid) (sendable-lambda () var)))))

;;> Assigns \var{value} (evaluated here) to \var{var} in address space
;;> \var{uid}.
(define-syntax var-set!
  (syntax-rules ()
    ((var-set! uid var value)
     (let ((v value))
       (remote-apply (uid->aspace uid) (sendable-lambda () (set! var v)))))))

;;> Displays \var{string} on the standard output of address space \var{uid}.
(define (display-remote uid string)
  (remote-run! (uid->aspace uid)
               (sendable-lambda ()
                 (display string) (newline) (flush-output-port))))
