;;;; Waiting with a deadline on the monotonic clock, by mailbox or mutex:
;;;; no loop sleeps and looks again.

;;> Chibi's dynamic-wind without its garbage (docs/speed.md): (in), then
;;> (body)'s value, (out) however body leaves, on Chibi's own wind points.
(define (wind in body out)
  (in)
  (wound (%dk) in body out))

(define (wound here in body out)
  (%dk (point! (make-vector 4) (+ 1 (vector-ref here 0)) in out here))
  (unwound here out (body)))

(define (unwound here out value)
  (%dk here)
  (out)
  value)

(define (point! p depth in out parent)
  (vector-set! p 0 depth)
  (vector-set! p 1 in)
  (vector-set! p 2 out)
  (vector-set! p 3 parent)
  p)

;;> srfi 18's mutex-lock! and mutex-unlock! as macros (\var{m} without effects): no timeout, no garbage.
(define-syntax lock!
  (syntax-rules ()
    ((_ m) (begin (if lock-order-checked? (taking! m))
                  (if (%mutex-lock! m #f #t)            ; no or, no not (docs/speed.md)
                      #t
                      (begin (thread-yield!) (mutex-lock! m))) ; as srfi 18's, once it failed
                  (if lock-order-checked? (took! m))))))

(define-syntax unlock!
  (syntax-rules ()
    ((_ m) (begin (if lock-order-checked? (released! m))
                  (%mutex-unlock! m #f #f)))))

;;> \var{value}, once \var{m} is unlocked: no let (docs/speed.md).
(define (unlocked m value)
  (unlock! m)
  value)

;; A procedure of the srfi 18 library that it does not export.
(define (srfi-18-primitive name)
  (eval name (module-env (find-module '(srfi 18)))))

(define %mutex-lock! (srfi-18-primitive '%mutex-lock!))
(define %mutex-unlock! (srfi-18-primitive '%mutex-unlock!))
(define thread-timeout? (srfi-18-primitive 'thread-timeout?))

;;> Applies \var{thunk} holding the mutex \var{m}, freed however thunk leaves.
(define (with-lock m thunk)
  (wind (lambda () (lock! m)) thunk (lambda () (unlock! m))))

;; As with-lock, calling (too-late) when m is not free by the deadline.
(define (with-lock-by m deadline too-late thunk)
  (if lock-order-checked? (taking! m))
  (if (mutex-lock! m (seconds-until deadline))
      (begin (if lock-order-checked? (took! m))
             (wind nothing thunk (lambda () (unlock! m))))
      (too-late)))

(define (nothing) #f)

;; Seconds from now to deadline, none if past; inexact (docs/speed.md).
(define (seconds-until deadline)
  (not-below-zero (- (inexact deadline) (monotonic-seconds))))

(define (not-below-zero x) (if (< x 0.) 0. x))

;; Frees m and waits on cv for left seconds; #f when none were left or they ran out.
(define (waited? m cv left)
  (and (> left 0.) (woken? m cv left)))

;;> srfi 18's (mutex-unlock! m cv [timeout]): frees \var{m} and waits on \var{cv}.
(define (unlock-waiting! m cv . timeout)
  (woken? m cv (if (pair? timeout) (car timeout) #f)))

;; As srfi 18's mutex-unlock!, seconds a number or #f, without its two
;; lets' closures and its rest list, once a wait (docs/speed.md).
(define (woken? m cv seconds)
  (if lock-order-checked? (released! m))
  (if (%mutex-unlock! m cv seconds)
      #t
      (begin (thread-yield!) (not (thread-timeout?)))))

;;; The lock order (docs/architecture.md), checked under MURDOCH_LOCK_ORDER:
;;; a thread holding a lock takes another only of a higher rank, else it
;;; writes both to standard error and to a file of that folder.

;; A mutex's rank, by the name it was made with; a name of no rank is a
;; break of the order wherever it is taken under another.
(define lock-ranks
  '((tasks . 2) (offers . 2)
    (team-keeping . 2.2) (handed . 2.5)
    (poses . 3) (running . 3) (subscriptions . 3)
    (connecting . 4.1) (connection-write . 4.2) (connections . 4.3) (peers . 4.4)
    (janitor . 4.5) (served-write . 4.55) (serving . 4.6)
    (trip-reconnect . 5) (trip . 5.1) (sequence . 5.1) (last-heard . 5.1)
    (datagram-calls . 5.1) (workers . 5.1) (proxies . 5.1) (abandoned . 5.1)
    (protected . 5.1) (fields-text . 5.1) (team . 5.1) (teams . 5.1) (feed . 5.1)
    (mailbox . 6) (gathering . 6)))

(define lock-order-folder (get-environment-variable "MURDOCH_LOCK_ORDER"))
(define lock-order-checked? (and lock-order-folder #t))

(define held-locks (make-hash-table eq?))   ; thread -> its locks, innermost first

(define (lock-rank m)
  (cond ((assq (mutex-name m) lock-ranks) => cdr)
        (else #f)))

(define (taking! m)
  (for-each (lambda (h)
              (if (not (and (lock-rank h) (lock-rank m) (< (lock-rank h) (lock-rank m))))
                  (lock-order-broken m h)))
            (hash-table-ref/default held-locks (current-thread) '())))

(define lock-order-report #f)               ; this process's file, once it broke the order

(define (lock-order-broken m h)
  (let ((line (call-with-output-string
               (lambda (out)
                 (write-string "lock order: took " out)
                 (write (mutex-name m) out)
                 (write-string " holding " out)
                 (write (mutex-name h) out)
                 (newline out)))))
    (write-string line (current-error-port))
    (if (not lock-order-report)
        (set! lock-order-report
              (open-output-file (string-append lock-order-folder "/"
                                               (number->string (current-process-id))))))
    (write-string line lock-order-report)
    (flush-output-port lock-order-report)))

(define (took! m)
  (hash-table-update!/default held-locks (current-thread) (lambda (ms) (cons m ms)) '()))

(define (released! m)
  (let ((ms (remove-first m (hash-table-ref/default held-locks (current-thread) '()))))
    (if (null? ms)
        (hash-table-delete! held-locks (current-thread))
        (hash-table-set! held-locks (current-thread) ms))))

(define (remove-first x xs)
  (cond ((null? xs) xs)
        ((eq? x (car xs)) (cdr xs))
        (else (cons (car xs) (remove-first x (cdr xs))))))

;;> Calls thunk; should it raise, calls undo on the way out (docs/speed.md).
(define (undo-on-raise undo thunk)
  (undone-after (undo-begun! undo) thunk))

(define (undone-after here thunk)
  (undo-ended here (thunk)))

;;> undo-on-raise in halves, for a caller whose thunk would be a closure
;;> made only to be passed: answers the wind point to give back to
;;> \scheme{undo-ended}, with the value of what ran between them.  Chibi
;;> evaluates arguments right to left, so the point is an argument of a
;;> procedure whose body runs what it guards.
(define (undo-begun! undo)
  (undo-pushed! (%dk) undo))

(define (undo-pushed! here undo)
  (%dk (point! (make-vector 4) (+ 1 (vector-ref here 0)) nothing undo here))
  here)

(define (undo-ended here value)
  (%dk here)
  value)

;;> (map proc items), a raising item giving (on-raise item e) (docs/speed.md).
(define (map-guarded proc items on-raise)
  (let ((done '()) (rest items))
    (let run ()
      (guard (e (#t (set! done (cons (on-raise (car rest) e) done))
                    (set! rest (cdr rest))
                    (run)))
        (let loop ()
          (when (pair? rest)
            (set! done (cons (proc (car rest)) done))
            (set! rest (cdr rest))
            (loop)))))
    (reverse done)))

;; A one-shot mailbox: the reader puts an answer, the caller takes it or
;; gives up; emptied by its taker once no other thread can put to it.
(define-lean-record-type mailbox
  (%make-mailbox mutex condvar value full?)
  mailbox?
  (mutex mailbox-mutex)
  (condvar mailbox-condvar)
  (value mailbox-value mailbox-value-set!)
  (full? mailbox-full? mailbox-full?-set!))

(define (make-mailbox)
  (%make-mailbox (make-mutex 'mailbox) (make-condition-variable) #f #f))

(define (mailbox-put! mb value)
  (lock! (mailbox-mutex mb))
  (mailbox-value-set! mb value)
  (mailbox-full?-set! mb #t)
  (condition-variable-broadcast! (mailbox-condvar mb))
  (unlock! (mailbox-mutex mb)))

;;> Empties mailbox \var{mb}, for its taker to wait on again.
(define (mailbox-empty! mb)
  (lock! (mailbox-mutex mb))
  (mailbox-value-set! mb #f)
  (mailbox-full?-set! mb #f)
  (unlock! (mailbox-mutex mb)))

;; The value, or (timed-out) past the deadline; SRFI-18 waits count whole seconds.
(define (mailbox-take mb deadline timed-out)
  (lock! (mailbox-mutex mb))
  (if (mailbox-full? mb)
      (unlocked (mailbox-mutex mb) (mailbox-value mb))
      (mailbox-wait mb deadline timed-out (seconds-until deadline))))

(define (mailbox-wait mb deadline timed-out left)
  (if (waited? (mailbox-mutex mb) (mailbox-condvar mb) left)
      (mailbox-take mb deadline timed-out)
      (begin (unlock! (mailbox-mutex mb))
             (timed-out))))

;;; Mailboxes by id: a connection's calls waiting for their answers

;;> The mailbox \var{table} holds for \var{id}, taken out, or #f; under the table's lock.
(define (take-mailbox! table id)
  (taken table id (hash-table-cell table id #f)))

;; hash-table-cell, and no let (docs/speed.md).
(define (taken table id cell)
  (and cell
       (begin (hash-table-delete! table id)
              (cdr cell))))

;;> The value in \var{cell} (from \scheme{hash-table-cell}), or \var{default} when it is #f.
(define (cell-value cell default) (if cell (cdr cell) default))

;;> Every mailbox of \var{table}, taken out of it, as the connection ended; under its lock.
(define (take-all-mailboxes! table)
  (let ((mbs (hash-table-values table)))
    (for-each (lambda (id) (hash-table-delete! table id))
              (hash-table-keys table))
    mbs))

;;; Gatherings: one wake for the answers to many calls

;;> A gathering: the poller hands in the answers to a caller's calls, and
;;> the caller wakes once, at the nth or its deadline, not n times.
(define-lean-record-type gathering
  (%make-gathering mutex condvar got wanted)
  gathering?
  (mutex gathering-mutex)
  (condvar gathering-condvar)
  (got gathering-got gathering-got-set!)
  (wanted gathering-wanted gathering-wanted-set!))

(define (make-gathering)
  (%make-gathering (lean-mutex 'gathering) (lean-condition-variable) 0 #f))

;; srfi 18's mutex and condition variable, made as lean records are
;; (sys/record.scm), their fields by their places in types.scm.
(define mutex-type (type-of (make-mutex 'gathering)))
(define bare-mutex (make-constructor "make-mutex" mutex-type))
(define condition-variable-type (type-of (make-condition-variable)))
(define bare-condition-variable
  (make-constructor "make-condition-variable" condition-variable-type))

(define (lean-mutex name)
  (filled-mutex (bare-mutex) name))

(define (filled-mutex m name)
  (slot-set! mutex-type m 0 name)
  (slot-set! mutex-type m 1 #f)
  (slot-set! mutex-type m 2 #f)
  (slot-set! mutex-type m 3 #f)
  m)

(define (lean-condition-variable)
  (filled-condition-variable (bare-condition-variable)))

(define (filled-condition-variable cv)
  (slot-set! condition-variable-type cv 0 #f)
  (slot-set! condition-variable-type cv 1 #f)
  (slot-set! condition-variable-type cv 2 #f)
  cv)

;;> Gives \var{item} \var{value} by \scheme{(put item value)} unless \scheme{(get item)} has one.
(define (gathering-put! g item value get put)
  (lock! (gathering-mutex g))
  (when (not (get item))
    (put item value)
    (gathering-got-set! g (+ 1 (gathering-got g)))
    (if (and (gathering-wanted g) (>= (gathering-got g) (gathering-wanted g)))
        (condition-variable-signal! (gathering-condvar g))))
  (unlock! (gathering-mutex g)))

;;> Waits until \var{n} answers have come (#t), or the deadline (#f).
(define (gathering-wait g n deadline)
  (lock! (gathering-mutex g))
  (gathering-wanted-set! g n)
  (if (>= (gathering-got g) n)
      (unlocked (gathering-mutex g) #t)
      (gathering-wait-on g n deadline (seconds-until deadline))))

(define (gathering-wait-on g n deadline left)
  (if (waited? (gathering-mutex g) (gathering-condvar g) left)
      (gathering-wait g n deadline)
      (begin (unlock! (gathering-mutex g)) (>= (gathering-got g) n))))
