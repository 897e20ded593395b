;;;; Waiting with a deadline: one clock, one way to wait.
;;
;; Every deadline in Murdoch is a moment on the monotonic clock
;; (monotonic-seconds), and every wait for another thread is a mailbox or
;; a mutex taken by a deadline: no loop sleeps and looks again.  (A wait
;; for a socket is the scheduler's port-wait!.)

;;> Chibi's dynamic-wind without its garbage (docs/speed.md, What Chibi
;;> charges): \scheme{(in)}, then \scheme{(body)}'s value, with
;;> \scheme{(out)} run however body leaves.  Its point is Chibi's (a vector
;;> of depth, in, out and parent in %dk), so call/cc and raise wind
;;> through it as through dynamic-wind's.
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

;;> \scheme{(mutex-lock! m)} and \scheme{(mutex-unlock! m)} of srfi 18,
;;> for a mutex taken with no timeout and freed with no condition
;;> variable, without the garbage of their optional arguments
;;> (docs/speed.md): the primitives that srfi 18's call.
(define (lock! m)
  (or (%mutex-lock! m #f #t)
      (begin (thread-yield!) (mutex-lock! m))))   ; as srfi 18's, once it failed

(define (unlock! m) (%mutex-unlock! m #f #f))

;;> \var{value}, once \var{m} is unlocked: no let (docs/speed.md).
(define (unlocked m value)
  (unlock! m)
  value)

;; A procedure of the srfi 18 library that it does not export.
(define (srfi-18-primitive name)
  (eval name (module-env (find-module '(srfi 18)))))

(define %mutex-lock! (srfi-18-primitive '%mutex-lock!))
(define %mutex-unlock! (srfi-18-primitive '%mutex-unlock!))

;;> Applies \var{thunk} holding the mutex \var{m}, which it frees however
;;> thunk leaves.
(define (with-lock m thunk)
  (wind (lambda () (lock! m)) thunk (lambda () (unlock! m))))

;; As with-lock, giving up with (too-late) when m is not free by the
;; deadline, on the monotonic clock.
(define (with-lock-by m deadline too-late thunk)
  (if (mutex-lock! m (seconds-until deadline))
      (wind nothing thunk (lambda () (unlock! m)))
      (too-late)))

(define (nothing) #f)

;; Seconds from now to deadline, none if it has passed; inexact, never
;; mixed with exact numbers (docs/speed.md).
(define (seconds-until deadline)
  (not-below-zero (- (inexact deadline) (monotonic-seconds))))

(define (not-below-zero x) (if (< x 0.) 0. x))

;; Frees m and waits on cv for left seconds, from seconds-until; #f when
;; none were left, or they ran out.
(define (waited? m cv left)
  (and (> left 0.) (mutex-unlock! m cv left)))

;;> Calls thunk; when it leaves by raising, calls undo on the way out: a
;;> wind point whose out is undo, taken off unrun when thunk returns, not
;;> a guard (docs/speed.md).
(define (undo-on-raise undo thunk)
  (undone-on-raise (%dk) undo thunk))

(define (undone-on-raise here undo thunk)
  (%dk (point! (make-vector 4) (+ 1 (vector-ref here 0)) nothing undo here))
  (unwound-quietly here (thunk)))

(define (unwound-quietly here value)
  (%dk here)
  value)

;;> (map proc items), where an item whose (proc item) raises gives
;;> (on-raise item e), under one handler, entered again only after a
;;> raise (docs/speed.md, What Chibi charges).
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

;; A one-shot mailbox: the reader thread puts an answer, the caller takes
;; it or gives up at its deadline.  Its taker may empty it for the next
;; (mailbox-empty!), once no other thread can still put to it.
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
  (lock! (mailbox-mutex mb))
  (mailbox-value-set! mb value)
  (mailbox-full?-set! mb #t)
  (condition-variable-broadcast! (mailbox-condvar mb))
  (unlock! (mailbox-mutex mb)))

;;> Empties mailbox \var{mb}, for its taker to wait on again: a worker's
;;> for its next job, say, instead of a new mutex and condition variable
;;> for each.
(define (mailbox-empty! mb)
  (lock! (mailbox-mutex mb))
  (mailbox-value-set! mb #f)
  (mailbox-full?-set! mb #f)
  (unlock! (mailbox-mutex mb)))

;; The mailbox's value, or (timed-out) once the deadline, on the monotonic
;; clock, has passed.  Chibi's SRFI-18 time objects count whole seconds, so
;; each wait is given as the seconds left.  No named let (docs/speed.md).
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

;;> The mailbox that \var{table} (id -> mailbox, an SRFI 69 table) holds
;;> for \var{id}, taken out of it; #f when it holds none.  The caller
;;> holds the lock that guards the table.
(define (take-mailbox! table id)
  (taken table id (hash-table-cell table id #f)))

;; hash-table-cell, and no let (docs/speed.md).
(define (taken table id cell)
  (and cell
       (begin (hash-table-delete! table id)
              (cdr cell))))

;;> The value in \var{cell}, from srfi 69's \scheme{hash-table-cell}, or
;;> \var{default} when it is #f, without hash-table-ref/default's closure.
(define (cell-value cell default) (if cell (cdr cell) default))

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
;;> shows it has one.  No wind, as put only sets a field (docs/speed.md).
(define (gathering-put! g item value get put)
  (lock! (gathering-mutex g))
  (when (not (get item))
    (put item value)
    (gathering-got-set! g (+ 1 (gathering-got g)))
    (if (and (gathering-wanted g) (>= (gathering-got g) (gathering-wanted g)))
        (condition-variable-signal! (gathering-condvar g))))
  (unlock! (gathering-mutex g)))

;;> Waits until \var{n} answers have come, answering #t, or until the
;;> deadline, answering #f.  No let (docs/speed.md).
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
