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
    (let ((g (make-gathering)))
      (finish-call (start-call a kind proc-code args-code deadline g)
                   g deadline seconds proc))))

;; A call sent, its answer to come to gathering g.
(define (start-call a kind proc-code args-code deadline g)
  (undo-on-raise
   (lambda () (note-unreachable! (aspace-uid a)))
   (lambda ()
     (send-call! (connection-to a deadline) kind proc-code args-code g))))

;; The answer to a pending call, by the deadline (on the monotonic
;; clock), which is \var{seconds} after the call began: the value, or a
;; remote-error.
(define (finish-call p g deadline seconds proc)
  (await-answers g (list p) deadline)
  (answer-value p seconds proc))

;; Waits until each pending call of ps has its answer, or the deadline
;; has passed.  A wait interrupted (Ctrl-C) gives up every call that has
;; none.
(define (await-answers g ps deadline)
  (undo-on-raise
   (lambda () (for-each give-up! ps))
   (lambda () (gathering-wait g (length ps) deadline))))

;; Forgets p, unless its answer came, and tells its callee.
(define (give-up! p)
  (if (and (not (pending-call-answer p)) (pending-call-connection p))
      (give-up-call! (pending-call-connection p) (pending-call-id p))))

;; What the answer of pending call p to a call of proc says: the value, or
;; a remote-error; none came within seconds, and p is given up.
;; Answers are (ack ID), (value ID VALUE), (error ID MESSAGE) or (lost).
(define (answer-value p seconds proc)
  (let ((uid (pending-call-uid p)))
    (match (pending-call-answer p)
      (#f (give-up! p) (timed-out uid proc seconds))
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
         (g (make-gathering))
         (started
          (capture-each aspace-uid
                        (lambda (a)
                          (list (aspace-uid a) #t
                                (if (local? a)
                                    (local-call kind proc args)
                                    (start-call a kind proc-code args-code
                                                deadline g))))
                        aspaces)))
    (await-answers g (filter-map started-call started) deadline)
    (capture-each car
                  (lambda (s)
                    (let ((p (started-call s)))
                      (if p (list (car s) #t (answer-value p seconds proc)) s)))
                  started)))

;; The pending call of an entry of send-all's, if it started one.
(define (started-call s)
  (and (cadr s) (pending-call? (car (cddr s))) (car (cddr s))))

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

(define *datagram-calls* (make-hash-table eqv?)) ; id -> (pending-call ...)
(define *datagram-calls-lock* (make-mutex 'datagram-calls))
(define *next-datagram-id* 0)

;; A new datagram call's id, whose answers from each of uids will come to
;; gathering g; answers it and their pending calls, in the order of uids.
(define (expect-answers! uids g)
  (with-lock *datagram-calls-lock*
    (lambda ()
      (set! *next-datagram-id* (+ *next-datagram-id* 1))
      (let* ((id *next-datagram-id*)
             (ps (map (lambda (uid) (make-pending-call uid #f id g #f)) uids)))
        (hash-table-set! *datagram-calls* id ps)
        (cons id ps)))))

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
       (cond ((find (lambda (p) (eq? (pending-call-uid p) uid)) waiting)
              => (lambda (p) (answer-call! p (list kind id value)))))))))

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
