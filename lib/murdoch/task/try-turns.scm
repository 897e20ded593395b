;;;; Tries in turn, part of (murdoch task rank): those that may ask the
;;;; same robot one at a time, best rank first (docs/allocation.md).

;;> A try's turn at its poser: its waiter, the robots it may ask (its
;;> claim), or #f for the whole lab, and the bell that lets it in.
(define-record-type try-turn
  (make-try-turn waiter claim bell)
  try-turn?
  (waiter try-turn-waiter)
  (claim try-turn-claim)
  (bell try-turn-bell))

;;> Queues \var{turn} here by rank (leave-try-turns!: takes it out), and
;;> rings the bell of each turn let-in lets in.
(define (join-try-turns! turn)
  (update-try-turns! (lambda (turns) (in-try-order turn turns)) '()))

(define (leave-try-turns! turn)
  (update-try-turns! (lambda (turns) (remove (lambda (t) (eq? t turn)) turns)) turn))

(define (update-try-turns! f leaving)
  (with-lock (tasks-lock)
    (lambda ()
      (let ((running (remove (lambda (t) (eq? t leaving)) (tries-running))))
        (let-values (((in out) (let-in (f (tries-waiting)) running)))
          (line-tries-running-set! (the-line) (append in running))
          (line-tries-waiting-set! (the-line) out)
          (for-each (lambda (t) (mailbox-put! (try-turn-bell t) #t)) in))))))

;; The turns of the tries running here, and of those waiting, best first.
(define (tries-running) (line-tries-running (the-line)))
(define (tries-waiting) (line-tries-waiting (the-line)))

;;> Whether a try here of another task than \var{w}, running or waiting,
;;> may ask robot \var{uid}, and so take it first.  Under (tasks-lock).
(define (claimed-by-others? w uid)
  (any (lambda (t)
         (and (not (eq? (try-turn-waiter t) w))
              (let ((claim (try-turn-claim t))) (or (not claim) (memq uid claim)))))
       (append (tries-running) (tries-waiting))))

;;> turns, waiting best first, with \var{turn} among them in rank order.
(define (in-try-order turn turns)
  (in-rank-order turn turns (lambda (t) (waiter-rank (try-turn-waiter t)))))

;;> Of \var{waiting}, turns best first, those that may try beside
;;> \var{running}: each clear of those running and of those before it.
;;> Answers the turns let in and those that still wait, in order.
(define (let-in waiting running)
  (let loop ((ts waiting) (blocking running) (in '()) (out '()))
    (cond ((null? ts) (values (reverse in) (reverse out)))
          ((clear-of? (car ts) blocking)
           (loop (cdr ts) (cons (car ts) blocking) (cons (car ts) in) out))
          (else (loop (cdr ts) (cons (car ts) blocking) in (cons (car ts) out))))))

;; Whether turn's claim shares no robot with any of turns'.
(define (clear-of? turn turns)
  (let ((claim (try-turn-claim turn)))
    (every (lambda (t)
             (let ((other (try-turn-claim t)))
               (and claim other (not (any (lambda (uid) (memq uid other)) claim)))))
           turns)))
