;;; (murdoch sys wait): wind as Chibi's dynamic-wind, the locks the remote
;;; layer takes on every call, undoing on a raise, and mailboxes by id;
;;; (murdoch sys record)'s records.
(import (scheme base) (scheme write) (srfi 18) (srfi 69) (chibi test)
        (only (chibi ast) gc) (murdoch sys) (only (murdoch sys wait) wind))

;; What ran, in order, through (note! x).
(define trail '())
(define (note! x) (set! trail (cons x trail)))
(define (trail-of thunk)
  (set! trail '())
  (guard (e (#t (note! (list 'raised e))))
    (note! (list 'value (thunk))))
  (reverse trail))

(define (winding name body)
  (wind (lambda () (note! (list 'in name))) body (lambda () (note! (list 'out name)))))

(test-begin "wait")

(test-group "wind, as dynamic-wind"
  (test "in, body, out, and the body's value"
      '((in a) (out a) (value 7))
    (trail-of (lambda () (winding 'a (lambda () 7)))))
  (test "out runs when the body raises"
      '((in a) (out a) (raised boom))
    (trail-of (lambda () (winding 'a (lambda () (raise 'boom))))))
  (test "out runs when the body escapes by a continuation"
      '((in a) (out a) (value escaped))
    (trail-of (lambda () (call/cc (lambda (k) (winding 'a (lambda () (k 'escaped))))))))
  (test "nested in Chibi's own dynamic-wind, each unwinds in turn"
      '((in a) (in b) (out b) (out a) (raised boom))
    (trail-of (lambda ()
                (winding 'a (lambda ()
                              (dynamic-wind (lambda () (note! '(in b)))
                                            (lambda () (raise 'boom))
                                            (lambda () (note! '(out b)))))))))
  (test "in runs again when a continuation re-enters the body"
      '((in a) (out a) (in a) (out a) (value 2))
    (trail-of (lambda ()
                (let ((k #f) (n 0))
                  (winding 'a (lambda ()
                                (call/cc (lambda (c) (set! k c)))
                                (set! n (+ n 1))))
                  (if (< n 2) (k #f) n))))))

(test-group "the locks"
  (let ((m (make-mutex)))
    (test "lock! takes a free mutex for this thread" #t
      (begin (lock! m) (eq? (mutex-state m) (current-thread))))
    (test "unlock! frees it" 'not-abandoned (begin (unlock! m) (mutex-state m)))
    (test "a second thread's lock! waits until it is freed"
        '(released got)
      (let ((order '()))
        (lock! m)
        (let ((t (make-thread (lambda () (lock! m) (set! order (cons 'got order))
                                      (unlock! m)))))
          (thread-start! t)
          (thread-sleep! 0.05)
          (set! order (cons 'released order))
          (unlock! m)
          (thread-join! t)
          (reverse order))))
    (test "with-lock frees the mutex when its thunk raises" 'not-abandoned
      (begin (guard (e (#t #f)) (with-lock m (lambda () (raise 'boom))))
             (mutex-state m)))
    (test "and srfi 18's mutex-lock! takes it after lock! and unlock!" #t
      (begin (lock! m) (unlock! m) (mutex-lock! m) (mutex-unlock! m) #t))))

(test-group "undo-on-raise"
  (test "undo does not run when the thunk returns" '((value 3))
    (trail-of (lambda () (undo-on-raise (lambda () (note! 'undone)) (lambda () 3)))))
  (test "undo runs when the thunk raises" '(undone (raised boom))
    (trail-of (lambda () (undo-on-raise (lambda () (note! 'undone))
                                        (lambda () (raise 'boom))))))
  (test "and when it escapes by a continuation" '(undone (value out))
    (trail-of (lambda ()
                (call/cc (lambda (k)
                           (undo-on-raise (lambda () (note! 'undone))
                                          (lambda () (k 'out))))))))
  (test "not for a raise after the thunk returned" '((raised later))
    (trail-of (lambda ()
                (undo-on-raise (lambda () (note! 'undone)) (lambda () 1))
                (raise 'later)))))

(test-group "undo-on-raise in halves"
  ;; The point is taken before the thunk runs: an argument of a call that runs it.
  (define (halves thunk)
    (trail-of (lambda () (ended (undo-begun! (lambda () (note! 'undone))) thunk))))
  (define (ended here thunk) (undo-ended here (thunk)))
  (test "undo does not run when what ran between returns" '((value 3))
    (halves (lambda () 3)))
  (test "undo runs when it raises" '(undone (raised boom))
    (halves (lambda () (raise 'boom)))))

;; Fields declared in another order than the constructor takes them.
(define-lean-record-type lean
  (make-lean c a)
  lean?
  (a lean-a)
  (b lean-b lean-b-set!)
  (c lean-c lean-c-set!))

(test-group "define-lean-record-type"
  (test "each field where the constructor put it" '(#t 1 3)
    (let ((r (make-lean 3 1)))
      (list (lean? r) (lean-a r) (lean-c r))))
  (test "set as Chibi's records are" '(2 4)
    (let ((r (make-lean 3 1)))
      (lean-b-set! r 2)
      (lean-c-set! r 4)
      (list (lean-b r) (lean-c r))))
  (test "another value is not one" '(#f #f) (list (lean? 5) (lean? (vector 3 1))))
  (test-error "an accessor refuses another record" (lean-a (make-gathering))))

(test-group "gatherings"
  (define (answer! item value) (set-car! item value))
  (test "a wait ends when the nth answer comes from another thread" '(#t (a) (b))
    (let ((g (make-gathering)) (x (list #f)) (y (list #f)))
      (thread-start! (make-thread (lambda ()
                                    (thread-sleep! 0.05)
                                    (gathering-put! g x 'a car answer!)
                                    (gathering-put! g y 'b car answer!))))
      (list (gathering-wait g 2 (+ (monotonic-seconds) 30)) x y)))
  (test "an item that has its answer keeps it" '(a)
    (let ((g (make-gathering)) (x (list #f)))
      (gathering-put! g x 'a car answer!)
      (gathering-put! g x 'b car answer!)
      x))
  (test "and a wait with too few answers ends at its deadline" #f
    (let ((g (make-gathering)) (x (list #f)))
      (gathering-put! g x 'a car answer!)
      (gathering-wait g 2 (+ (monotonic-seconds) 0.1)))))

(test-group "deadlines"
  ;; (gc) answers the bytes it freed: what the thunk made, 1,000 times.
  (define (bytes-each thunk)
    (gc)
    (do ((i 0 (+ i 1))) ((= i 1000)) (thunk))
    (quotient (gc) 1000))
  (define past (- (monotonic-seconds) 0.5))
  (test "the seconds left before an exact deadline are inexact" #t
    (inexact? (seconds-until (+ 10 (exact (floor (monotonic-seconds)))))))
  (test "and none once it has passed" 0. (seconds-until 0))
  (test "a mailbox's wait ends at an exact deadline" 'late
    (mailbox-take (make-mailbox) (exact (floor (monotonic-seconds)))
                  (lambda () 'late)))
  ;; Chibi makes an inexact number that meets an exact one exact, a ratio
  ;; of bignums: (positive? 0.25) made 3.5 KB, and every wait did so twice.
  (test "a wait's deadline makes no ratio of bignums" #t
    (let ((g (make-gathering)) (mb (make-mailbox)))
      (< (max (bytes-each (lambda () (gathering-wait g 1 past)))
              (bytes-each (lambda () (mailbox-take mb past (lambda () #f)))))
         1000))))

(test-group "a mailbox emptied for the next"
  (let ((mb (make-mailbox)))
    (mailbox-put! mb 'first)
    (test "its taker has the first value" 'first
      (mailbox-take mb (+ (monotonic-seconds) 5) (lambda () 'late)))
    (mailbox-empty! mb)
    (test "emptied, it waits again until its deadline" 'late
      (mailbox-take mb (+ (monotonic-seconds) 0.05) (lambda () 'late)))
    (test "and takes the next value that another thread puts" 'second
      (begin
        (thread-start! (make-thread (lambda ()
                                      (thread-sleep! 0.05)
                                      (mailbox-put! mb 'second))))
        (mailbox-take mb (+ (monotonic-seconds) 30) (lambda () 'late))))))

(test-group "mailboxes by id"
  (let ((table (make-hash-table eqv?)))
    (hash-table-set! table 7 'seven)
    (test "take-mailbox! answers the mailbox and takes it out" '(seven #f)
      (let* ((taken (take-mailbox! table 7))
             (left (hash-table-ref/default table 7 #f)))
        (list taken left)))
    (test "or #f for an id it does not hold" #f (take-mailbox! table 8))))

(test-end)
(test-exit)
