;;;; remote-run! and remote-apply (thesis §3.3.2), and their -all forms.
;;
;; A call encodes its procedure and arguments (sendable.scm), sends them
;; on the connection to its target (connection.scm) and awaits the answer
;; by its deadline: the value, or a remote-error of one of its kinds.

(define (call a kind proc args)
  (check-not-abandoned (if (eq? kind 'run) "remote-run!" "remote-apply"))
  (let* ((seconds (current-timeout))
         (proc-code (encode proc (lab-environment) "the procedure"))
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
    (match answer
      (('ack . _) #t)
      (('value id value) (decode-value value))
      (('error id message)
       (remote-error 'raised uid (describe-procedure proc) message))
      (('lost)
       (note-unreachable! uid)
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

(define (call-all aspaces kind proc args)
  (let ((who (if (eq? kind 'run) "remote-run-all!" "remote-apply-all")))
    (check-not-abandoned who)
    (for-each (lambda (a) (check-aspace who a)) aspaces))
  (send-all aspaces kind proc args
            (encode proc (lab-environment) "the procedure")
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

;; A call to this address space is a remote call too: an abandoned thread
;; stops at it (abandon.scm), as a component cut off from its poser whose
;; commands go to its own address space must.
(define (local-call kind proc args)
  (check-not-abandoned (if (eq? kind 'run) "remote-run!" "remote-apply"))
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
              (cons (encode (car args) (lab-environment)
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

;;; The answers to datagram calls
;;
;; A call sent to the whole lab by one multicast datagram (delivery.scm)
;; is answered by each address space over its own connection, with an
;; answer frame, which that connection's reader hands here.

(define *datagram-calls* (make-hash-table eqv?)) ; id -> ((uid . mailbox) ...)
(define *datagram-calls-lock* (make-mutex 'datagram-calls))
(define *next-datagram-id* 0)

;; A new datagram call's id, whose answers from each of uids will reach
;; their mailboxes in waiting, ((uid . mailbox) ...).
(define (expect-answers! waiting)
  (with-lock *datagram-calls-lock*
    (lambda ()
      (set! *next-datagram-id* (+ *next-datagram-id* 1))
      (hash-table-set! *datagram-calls* *next-datagram-id* waiting)
      *next-datagram-id*)))

;; Nobody waits for the answers to datagram call id any longer.
(define (forget-answers! id)
  (with-lock *datagram-calls-lock*
    (lambda () (hash-table-delete! *datagram-calls* id))))

;; Hands an (answer ID KIND VALUE) frame from address space uid to the
;; call that waits for it; one for a call no longer waited for is dropped.
(define (take-datagram-answer! uid message)
  (match message
    (('answer id kind value)
     (let ((waiting (with-lock *datagram-calls-lock*
                      (lambda ()
                        (hash-table-ref/default *datagram-calls* id '())))))
       (cond ((assq uid waiting)
              => (lambda (w) (mailbox-put! (cdr w) (list kind id value)))))))))

;;; The prober

(define probe-seconds 1)

;; Tries each address space out of the live set every probe-seconds, and
;; puts back each that answers.
(define (prober)
  (thread-sleep! probe-seconds)
  (for-each (lambda (uid)
              (guard (e (#t #f))       ; still away
                (parameterize ((remote-timeout probe-seconds))
                  (call (uid->aspace uid) 'apply local-aspace-uid '()))
                (note-reachable! uid)))
            (unreachable-uids))
  (prober))
