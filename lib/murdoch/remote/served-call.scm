;;;; Served calls, part of (murdoch remote serve): reading, running, answering.

;; A call read from a connection or the group, answered their way (reply!).
(define-lean-record-type served-call
  (make-served-call caller id kind proc-code args-code answer)
  served-call?
  (caller served-call-caller)           ; its uid, or for the group its aspace
  (id served-call-id)
  (kind served-call-kind)               ; run or apply
  (proc-code served-call-proc-code)
  (args-code served-call-args-code)
  (answer served-call-answer))          ; (answer C KIND VALUE)

;;> Answers served call \var{c}: \var{kind} ack, value or error, and its \var{value}.
(define-syntax reply!
  (syntax-rules () ((_ c kind value) ((served-call-answer c) c kind value))))

;; A thread reading s's calls, and the call it runs until answered.
(define-record-type reading
  (make-reading serving call)
  reading?
  (serving reading-serving)
  (call reading-call reading-call-set!))

;; Runs (read-on r) while this thread is s's reader, under one handler
;; (docs/speed.md).  An error in r's call is answered by (answer-error
;; call e) once its output is flushed; any other goes to (other-failure e).
(define (read-calls s read-on answer-error other-failure)
  (let ((r (make-reading s #f)))
    (serving-reading-set! s r)
    (let again ()
      (guard (e ((reading-call r)
                 => (lambda (c)
                      (flush-call-ports!)
                      (reading-call-set! r #f)
                      (let ((still (inline-apply-ends! s)))
                        (answer-error c e)
                        (if still (again)))))
                (#t (other-failure e)
                    (if (reader? s) (again))))
        (read-on r)))))

(define-syntax serve-apply
  (syntax-rules ()
    ((_ r s c)
     (begin (inline-apply-begins! s)
            ;; Answered while the call is r's; a value too large gets the error.
            (reply! c 'value (encoded-result c))
            (reading-call-set! r #f)
            (inline-apply-ends! s)))))

;; Runs call c: a run is acknowledged once decoded, and runs in a worker;
;; an apply runs here until the janitor hands the connection on.
(define (serve-call r c)
  (reading-call-set! r c)
  (if (eq? (served-call-kind c) 'run)
      (serve-run r c (decode-call c))
      (serve-apply r (reading-serving r) c)))

(define (serve-run r c thunk)
  (reading-call-set! r #f)
  (reply! c 'ack #t)
  (run-in-worker thunk))

;; What a connection knows after hello: the caller, the nonces, the counts.
(define-record-type greeting
  (make-greeting uid caller-nonce nonce text write-lock answer count sent flushed)
  greeting?
  (uid greeting-uid)
  (caller-nonce greeting-caller-nonce)  ; our answers are MACed with it
  (nonce greeting-nonce)                ; the caller's frames are
  (text greeting-text)                  ; see frame-text
  (write-lock greeting-write-lock)
  (answer greeting-answer)              ; a served call's (reply!)
  (count greeting-count greeting-count-set!)    ; frames read
  (sent greeting-sent greeting-sent-set!)       ; frames written
  (flushed greeting-flushed greeting-flushed-set!)) ; sent when last flushed

(define (greet! s hello)
  (check-message hello '(hello) "a hello")
  (learn-aspace! (make-aspace (message-field hello 'uid) (message-field hello 'host)
                              (message-field hello 'port)))
  (let* ((caller-nonce (message-field hello 'nonce))
         (g (make-greeting (message-field hello 'uid) caller-nonce (random-hex 16)
                           (open-output-string) (make-mutex 'served-write)
                           (lambda (c kind value) (answer-call s c kind value))
                           0 0 0)))
    (serving-greeting-set! s g)
    (serving-deadline-set! s #f)
    (serving-read-on-set! s (lambda () (serve-greeted s)))
    (send-frame! (serving-out s) (greeting-text g) caller-nonce 0
                 (make-message 'welcome (local-aspace-uid) (greeting-nonce g)))))

(define-syntax read-on
  (syntax-rules () ((_ s r) (serve-read! s r (read-served s)))))

(define (serve-greeted s)
  (read-calls s (lambda (r) (read-on s r))
              (lambda (c e)
                (let-go-of-writes! s)
                (reply! c 'error (error-message-naming e))
                (flush-if-idle! s (serving-greeting s)))
              raise))

;; The served call message asks for: (KIND ID PROC ARGS), wire/frame.scm's
;; table (by car and cdr: docs/speed.md).
(define-syntax served-call-of
  (syntax-rules ()
    ((_ message uid answer)
     (make-served-call uid (message-id message) (car message)
                       (car (cdr (cdr message))) (car (cdr (cdr (cdr message))))
                       answer))))

;; Serves one frame from uid: a call, answered by answer, or a notice.
(define-syntax serve-frame
  (syntax-rules ()
    ((_ r uid answer message)
     (if (memq (car message) '(run apply))
         (serve-call r (served-call-of message uid answer))
         (serve-notice (reading-serving r) uid message)))))

;; No unless, nor not below: each a call to Chibi's not (docs/speed.md).
(define (serve-read! s r message)
  (if (eof-object? message)
      message
      (begin (serve-frame r (greeting-uid (serving-greeting s))
                          (greeting-answer (serving-greeting s)) message)
             (flush-if-idle! s (serving-greeting s))
             (if (reader? s) (read-on s r)))))

(define (answer-call s c kind value)
  (if (eq? kind 'ack)
      (answer! s (serving-greeting s) (make-message 'ack (served-call-id c)) #f)
      (answer! s (serving-greeting s) (make-message kind (served-call-id c) value)
               #t)))

;; No or, whose let makes a closure (docs/speed.md).
(define-syntax flush-now?
  (syntax-rules ()
    ((_ s last?) (if (reader? s) (and last? (null? (serving-frames s))) #t))))

;; A caller that left makes this raise, and the connection end; a message
;; too large raises before its count is taken.
(define-syntax write-answer!
  (syntax-rules ()
    ((_ s g message)
     (begin (write-message! (serving-out s) (greeting-text g) message
                            (greeting-caller-nonce g) (+ 1 (greeting-sent g)))
            (greeting-sent-set! g (+ 1 (greeting-sent g)))))))

;; The caller holds the write lock.
(define-syntax flush!
  (syntax-rules ()
    ((_ s g) (begin (flush-output-port (serving-out s))
                    (greeting-flushed-set! g (greeting-sent g))))))

;; The reader's answers wait in the buffer until it has read every call
;; that arrived, for one write.  A value or error with no call behind it is
;; flushed under the lock; an ack waits for flush-if-idle!.  The lock is
;; taken by lock! (docs/speed.md); the reader's handlers let go after a raise.
(define (answer! s g message last?)
  (lock! (greeting-write-lock g))
  (write-answer! s g message)
  (if (flush-now? s last?) (flush! s g))
  (unlock! (greeting-write-lock g)))

;; Nothing to flush after a frame that had no answer; under the write lock.
(define (flush-if-idle! s g)
  (cond ((= (greeting-flushed g) (greeting-sent g)))
        ((null? (serving-frames s))
         (lock! (greeting-write-lock g))
         (flush! s g)
         (unlock! (greeting-write-lock g)))))

;; Lets go of s's write lock, should a raise (see answer!) have left it held.
(define (let-go-of-writes! s)
  (let ((g (serving-greeting s)))
    (if (and g (eq? (mutex-state (greeting-write-lock g)) (current-thread)))
        (unlock! (greeting-write-lock g)))))

;; Serves a frame that needs no answer: an answer or an abandon (by cond).
(define (serve-notice s uid message)
  (if (eq? (car message) 'answer)
      (take-datagram-answer! uid message)
      (abandon-call! s (message-id message))))

(define-syntax served-procedure
  (syntax-rules ()
    ((_ c) (checked-procedure (decode-value (served-call-proc-code c))))))

(define-syntax served-arguments
  (syntax-rules ()
    ((_ c proc) (decode-value (screened (served-call-args-code c) proc)))))

;; The application run c asks for, as a thunk that runs it in the sandbox.
(define (decode-call c)
  (let* ((proc (served-procedure c))
         (args (served-arguments c proc)))
    (lambda () (call-in-sandbox proc args))))

;; What c's application answers, encoded (no thunk, nor let: docs/speed.md).
(define (encoded-result c)
  (encoded-application c (served-procedure c)))

(define (encoded-application c proc)
  (encode (call-in-sandbox proc (served-arguments c proc)) (lab-environment) "the result"))

;; Global: each layer adds its own as it loads (screen-calls!).
(define *screens* '())

;;> Passes the arguments of a call of \var{proc}, as read, through \var{screen}, which
;;> leaves out the code this address space will not run, before they are decoded.
;;> Arguments it does not know, it answers as they are.
(define (screen-calls! proc screen)
  (set! *screens* (cons (cons proc screen) *screens*)))

(define (screened args-code proc)
  (let ((entry (assq proc *screens*)))
    (if entry ((cdr entry) args-code) args-code)))

(define (checked-procedure proc)
  (if (procedure? proc) proc (error "not a procedure" proc)))
