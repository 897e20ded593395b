;;;; remote-run! and remote-apply (thesis §3.3.2), and their -all forms.

;; A call leaving this address space, encoded once for all its targets.
(define-lean-record-type call
  (make-call kind proc args proc-code args-code seconds)
  call?
  (kind call-kind)                      ; run or apply
  (proc call-proc)
  (args call-args)
  (proc-code call-proc-code)            ; as encode gives them
  (args-code call-args-code)
  (seconds call-seconds))               ; its answers are awaited so long

;;> The call of \var{kind}, run or apply, of \var{proc} to \var{args}, encoded.
(define (new-call kind proc args)
  (make-call kind proc args (encode proc (lab-environment) "the procedure")
             (encode-arguments args) (current-timeout)))

;;> The outcome of a call to one of many address spaces.
(define-record-type result
  (make-result uid ok? value)
  result?
  (uid result-uid)
  (ok? result-ok?)                      ; #t when it answered
  (value result-value))                 ; the value, or what went wrong

(define (result->list r) (list (result-uid r) (result-ok? r) (result-value r)))

(define (caller-name kind) (if (eq? kind 'run) "remote-run!" "remote-apply"))

;; No let, whose closure every call would make (docs/speed.md).
(define (call-to a kind proc args)
  (check-not-abandoned (caller-name kind))
  (call-gathered a (new-call kind proc args)))

(define (call-gathered a c)
  (call-by a c (+ (monotonic-seconds) (call-seconds c)) (make-gathering)))

(define (call-by a c deadline g)
  (finish-call (start-call a (call-tail c) deadline g) g deadline c))

(define (call-tail c) (tail-of c *last-tail*))

;; Global: the last call's text but its id, #(KIND PROC-CODE ARGS-CODE TAIL),
;; replaced whole; a call of the same encodings (eq?) is written from it.
(define *last-tail* (vector #f #f #f #f))

(define (tail-of c last)
  (if (and (eq? (vector-ref last 1) (call-proc-code c))
           (eq? (vector-ref last 2) (call-args-code c))
           (eq? (vector-ref last 0) (call-kind c)))
      (vector-ref last 3)
      (new-tail! c (message-without-id (call-kind c)
                                       (list (call-proc-code c) (call-args-code c))))))

(define (new-tail! c tail)
  (set! *last-tail* (vector (call-kind c) (call-proc-code c) (call-args-code c) tail))
  tail)

;; A call sent to a, answered to gathering g; a peer out of reach is noted so.
(define (start-call a tail deadline g)
  (send-call! (connection-to a deadline) tail g))

;; The answer to p, pending call c, by the deadline: value or remote-error.
(define (finish-call p g deadline c)
  (await-answers g (list p) deadline)
  (answer-value p c))

;; Waits for each pending call of ps, or the deadline; a wait interrupted
;; (Ctrl-C) gives up every call that has no answer.  One closure, not two.
(define (await-answers g ps deadline)
  (awaited g ps deadline (undo-begun! (lambda () (for-each give-up! ps)))))

(define (awaited g ps deadline here)
  (undo-ended here (gathering-wait g (length ps) deadline)))

;; Forgets p, unless its answer came, and tells its callee.
(define (give-up! p)
  (if (and (not (pending-call-answer p)) (pending-call-connection p))
      (give-up-call! (pending-call-connection p) (pending-call-id p))))

;; What pending call p's answer says: the value, or a remote-error (none
;; came in time: p is given up).  No match, no let (docs/speed.md).
(define (answer-value p c)
  (answer-says p (pending-call-answer p) c))

(define (answer-says p answer c)
  (cond ((not answer)
         (give-up! p)
         (timed-out (pending-call-uid p) (call-proc c) (call-seconds c)))
        ((eq? (car answer) 'value) (decode-value (answer-field answer)))
        ((eq? (car answer) 'ack) #t)
        ((eq? (car answer) 'error)
         (remote-error 'raised (pending-call-uid p) (describe-procedure (call-proc c))
                       (answer-field answer)))
        (else
         (note-unreachable! (pending-call-uid p))
         (remote-error 'unreachable (pending-call-uid p)
                       (describe-procedure (call-proc c)) "connection lost"))))

;; The field after the id: a value answer's value, an error's message.
(define (answer-field answer) (car (cddr answer)))

(define (timed-out uid proc seconds)
  (note-unreachable! uid)
  (no-answer uid proc seconds))

;;> Raises the error of a call of \var{proc} that \var{uid} did not answer
;;> within \var{seconds}, leaving uid in the live set.
(define (no-answer uid proc seconds)
  (remote-error 'timed-out uid (describe-procedure proc)
                (string-append "no answer within " (number->string seconds) " s")))

;;> Applies \var{proc} to \var{args} in each of \var{aspaces} at once:
;;> (uid #t value) for each that answered, (uid #f message) for each that
;;> failed or timed out, in their order; as long as the slowest answer.
(define (remote-apply-all aspaces proc . args)
  (map result->list (call-all aspaces 'apply proc args)))

;;> As remote-apply-all, with remote-run!: the values are #t.
(define (remote-run-all! aspaces proc . args)
  (map result->list (call-all aspaces 'run proc args)))

;; An outcome stays a list, which the REPL shows as it reads.

;;> The uid of outcome \var{o}, one of remote-apply-all's answers.
(define (outcome-uid o) (car o))

;;> Whether the address space of outcome \var{o} answered.
(define (outcome-ok? o) (cadr o))

;;> The value of outcome \var{o} when it answered, else why not.
(define (outcome-value o) (car (cddr o)))

;;> As remote-apply-all and remote-run-all!, for \var{kind}: a result each.
(define (call-all aspaces kind proc args)
  (let ((who (if (eq? kind 'run) "remote-run-all!" "remote-apply-all")))
    (check-not-abandoned who)
    (for-each (lambda (a) (check-aspace who a)) aspaces))
  (send-all aspaces (new-call kind proc args)))

;;> Sends call \var{c} to each of \var{aspaces}, then awaits the answers.
(define (send-all aspaces c)
  (let* ((deadline (+ (monotonic-seconds) (call-seconds c)))
         (g (make-gathering))
         (tail (call-tail c))
         ;; A pending call for each call sent; a result for the rest.
         (started
          (capture-each aspace-uid
                        (lambda (a)
                          (if (local? a)
                              (make-result (aspace-uid a) #t
                                           (local-call (call-kind c) (call-proc c)
                                                       (call-args c)))
                              (start-call a tail deadline g)))
                        aspaces)))
    (await-answers g (filter pending-call? started) deadline)
    (capture-each started-uid
                  (lambda (x)
                    (if (pending-call? x)
                        (make-result (pending-call-uid x) #t (answer-value x c))
                        x))
                  started)))

(define (started-uid x)
  (if (pending-call? x) (pending-call-uid x) (result-uid x)))

;;> Applies each of \var{procs} to \var{args} at once, a proxy where it
;;> was made; a result each, a call that raised or stopped a failure.
(define (apply-each procs args)
  (let* ((deadline (+ (monotonic-seconds) (current-timeout)))
         (g (make-gathering))
         (started (capture-each maker-uid (lambda (p) (start-apply p args deadline g))
                                procs)))
    (await-answers g (filter-map (lambda (x) (and (pair? x) (car x))) started) deadline)
    (capture-each (lambda (x) (if (pair? x) (pending-call-uid (car x)) (result-uid x)))
                  (lambda (x)
                    (if (pair? x)
                        (make-result (pending-call-uid (car x)) #t
                                     (answer-value (car x) (cdr x)))
                        x))
                  started)))

(define (start-apply p args deadline g) ; (pending-call . call), or p's result
  (if (eq? (maker-uid p) (local-aspace-uid))
      (make-result (local-aspace-uid) #t (apply p args))
      (begin (check-not-abandoned (caller-name 'apply))
             (let ((c (new-call 'apply p args)))
               (cons (start-call (uid->aspace (maker-uid p)) (call-tail c) deadline g) c)))))

(define (maker-uid p)
  (let ((ref (proxy-procedure-ref p)))
    (if ref (proxy-ref-uid ref) (local-aspace-uid))))

;; A call to this address space is a remote call too, so an abandoned
;; thread stops at it (code/abandon.scm).
(define (local-call kind proc args)
  (check-not-abandoned (caller-name kind))
  (if (eq? kind 'run)
      (begin (run-in-worker (lambda () (apply proc args))) #t)
      (apply-here (local-aspace-uid) proc args)))

;;> The result of \scheme{(thunk)} as that of \var{uid}, or why it raised.
(define (capture uid thunk)
  (guard (e (#t (failure-result uid e)))
    (make-result uid #t (thunk))))

(define (failure-result uid e)
  (make-result uid #f (error-message e)))

;;> (map entry items); an item whose entry raised gives its failure's result.
(define (capture-each uid-of entry items)
  (map-guarded entry items (lambda (item e) (failure-result (uid-of item) e))))

;; No named let, whose closure each call would make (docs/speed.md).
(define (encode-arguments args) (encoded-arguments args 1))

(define (encoded-arguments args i)
  (if (null? args)
      '()
      ;; Named only for an error (docs/speed.md, What Chibi charges).
      (cons (encode (car args) (lab-environment)
                    (lambda () (string-append "argument " (number->string i))))
            (encoded-arguments (cdr args) (+ i 1)))))

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
;;> \var{a}; returns #t once \var{a} has acknowledged.
(define (remote-run! a proc . args)
  (check-aspace "remote-run!" a)
  (if (local? a)
      (local-call 'run proc args)
      (call-to a 'run proc args)))

;;> Applies \var{proc} to \var{args} in address space \var{a} and returns
;;> the result; a remote-error when it raised, the connection broke, or no
;;> answer came within (remote-timeout) seconds, connecting included.
(define (remote-apply a proc . args)
  (check-aspace "remote-apply" a)
  (if (local? a)
      (local-call 'apply proc args)
      (call-to a 'apply proc args)))

;;; The answers to datagram calls, handed here by each peer's connection reader.

(define-record-type datagram-calls
  (make-datagram-calls waiting lock next-id)
  datagram-calls?
  (waiting datagram-calls-waiting)      ; id -> (places . pending-calls vector)
  (lock datagram-calls-lock)
  (next-id datagram-calls-next-id datagram-calls-next-id-set!))

;; Global: any connection's reader hands in answers to the process's calls.
(define *datagram-calls* (make-datagram-calls (make-hash-table eq?)
                                              (make-mutex 'datagram-calls) 0))

(define (with-datagram-calls thunk)
  (with-lock (datagram-calls-lock *datagram-calls*) thunk))

;; Whom a datagram call waits for: the live set but this address space,
;; and each one's place, by which an answer finds its call (docs/speed.md).
(define-record-type others
  (make-others live uids places)
  others?
  (live others-live)                    ; the live-aspaces list, this made of
  (uids others-uids)                    ; the live uids but ours
  (places others-places))               ; uid -> its place in uids

;; Global: the peers of the process's one address space.
(define *others* (make-others #f '() (make-hash-table eq?)))

;;> The others a datagram call to the live set waits for.
(define (datagram-others)
  (if (eq? (others-live *others*) (live-aspaces))
      *others*
      (others-now! (live-aspaces))))

(define (others-now! live)
  (let* ((uids (remove (lambda (uid) (eq? uid (local-aspace-uid)))
                       (map aspace-uid live)))
         (o (make-others live uids (make-hash-table eq?))))
    (for-each (lambda (uid i) (hash-table-set! (others-places o) uid i))
              uids (iota (length uids)))
    (set! *others* o)
    o))

;; A new datagram call's id; its pending calls, o's order, answer to gathering g.
(define (expect-answers! o g)
  (with-datagram-calls
    (lambda ()
      (let* ((id (+ 1 (datagram-calls-next-id *datagram-calls*)))
             (ps (map (lambda (uid) (make-pending-call uid #f id g #f))
                      (others-uids o))))
        (datagram-calls-next-id-set! *datagram-calls* id)
        (hash-table-set! (datagram-calls-waiting *datagram-calls*) id
                         (cons (others-places o) (list->vector ps)))
        (cons id ps)))))

;; What datagram call id waits for, (places . pending-calls), or #f.
(define (datagram-calls-waiting-for id)
  (lock! (datagram-calls-lock *datagram-calls*))
  (cell-value (unlocked (datagram-calls-lock *datagram-calls*)
                        (hash-table-cell (datagram-calls-waiting *datagram-calls*)
                                         id #f))
              #f))

(define (forget-answers! id)
  (with-datagram-calls
    (lambda () (hash-table-delete! (datagram-calls-waiting *datagram-calls*) id))))

;; Hands uid's (answer ID KIND VALUE) to its call, or drops it (no let).
(define (take-datagram-answer! uid message)
  (answer-datagram-call! (pending-of uid (datagram-calls-waiting-for
                                          (message-id message)))
                         message))

;; The pending call of uid in waiting, (places . pending-calls), or #f.
(define (pending-of uid waiting)
  (and waiting
       (pending-at (cell-value (hash-table-cell (car waiting) uid #f) #f)
                   (cdr waiting))))

(define (pending-at place pending-calls)
  (and place (vector-ref pending-calls place)))

(define (answer-datagram-call! p message)
  (if p
      (answer-call! p (list (datagram-answer-kind message) (message-id message)
                            (datagram-answer-value message)))))

(define (datagram-answer-kind message) (list-ref message 2))
(define (datagram-answer-value message) (list-ref message 3))

;;; The prober

(define probe-seconds 1)

;; Tries each address space out of the live set every probe-seconds.
(define (prober)
  (thread-sleep! probe-seconds)
  (for-each (lambda (uid)
              (guard (e (#t #f))       ; still away
                (parameterize ((remote-timeout probe-seconds))
                  (call-to (uid->aspace uid) 'apply local-aspace-uid '()))
                (note-reachable! uid)))
            (unreachable-uids))
  (prober))
