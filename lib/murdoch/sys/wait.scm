;;;; Waiting with a deadline: one clock, one way to wait.
;;
;; Every deadline in Murdoch is a moment on the monotonic clock
;; (monotonic-seconds), and every wait for another thread is a mailbox or
;; a mutex taken by a deadline: no loop sleeps and looks again.  (A wait
;; for a socket is the scheduler's port-wait!.)

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
;; dynamic-wind, not a guard, on the path of every call (docs/speed.md).
(define (undo-on-raise undo thunk)
  (let ((done #f))
    (dynamic-wind (lambda () #f)
                  (lambda () (let ((value (thunk))) (set! done #t) value))
                  (lambda () (if (not done) (undo))))))

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

;;; Mailboxes by id: a connection's calls waiting for their answers

;;> The mailbox that \var{table} (id -> mailbox, an SRFI 69 table) holds
;;> for \var{id}, taken out of it; #f when it holds none.  The caller
;;> holds the lock that guards the table.
(define (take-mailbox! table id)
  (let ((mb (hash-table-ref/default table id #f)))
    (hash-table-delete! table id)
    mb))

;;> Every mailbox of \var{table}, taken out of it: the connection ended,
;;> and no answer will come to them.  The caller holds the table's lock.
(define (take-all-mailboxes! table)
  (let ((mbs (hash-table-values table)))
    (for-each (lambda (id) (hash-table-delete! table id))
              (hash-table-keys table))
    mbs))

;;; Gatherings: one wake for the answers to many calls

;;> A gathering: the poller hands in the answers to a caller's calls one
;;> at a time, and the caller, waiting for n of them, wakes once, when the
;;> nth has come or at its deadline; a mailbox each would wake it n times.
(define-record-type gathering
  (%make-gathering mutex condvar got wanted)
  gathering?
  (mutex gathering-mutex)
  (condvar gathering-condvar)
  (got gathering-got gathering-got-set!)
  (wanted gathering-wanted gathering-wanted-set!))

(define (make-gathering)
  (%make-gathering (make-mutex) (make-condition-variable) 0 #f))

;;> Gives \var{item} the answer \var{value}, by \scheme{(put item value)},
;;> under the gathering's lock, and counts it, unless \scheme{(get item)}
;;> shows it has one.  No dynamic-wind, since put only sets a field, and
;;> no closure made: both would cost every answer (docs/speed.md).
(define (gathering-put! g item value get put)
  (let ((m (gathering-mutex g)))
    (mutex-lock! m)
    (when (not (get item))
      (put item value)
      (let ((got (+ 1 (gathering-got g))))
        (gathering-got-set! g got)
        (if (and (gathering-wanted g) (>= got (gathering-wanted g)))
            (condition-variable-signal! (gathering-condvar g)))))
    (mutex-unlock! m)))

;;> Waits until \var{n} answers have come, answering #t, or until the
;;> deadline, answering #f.
(define (gathering-wait g n deadline)
  (let ((m (gathering-mutex g)))
    (let loop ()
      (mutex-lock! m)
      (gathering-wanted-set! g n)
      (if (>= (gathering-got g) n)
          (begin (mutex-unlock! m) #t)
          (let ((left (seconds-until deadline)))
            (if (and (positive? left)
                     (mutex-unlock! m (gathering-condvar g) left))
                (loop)
                (begin (mutex-unlock! m) (>= (gathering-got g) n))))))))
