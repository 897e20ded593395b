;;; A poser's tries in turn (lib/murdoch/task/try-turns.scm, let-in): tries
;;; that may ask the same robot never run together, a try for the whole
;;; lab runs alone, none waits that could run, none passes a better-ranked
;;; one that may ask its robots, and every one runs in the end.  Checked
;;; on seeded runs of turns that join and leave at random.
(import (scheme base) (srfi 1) (srfi 27) (chibi test)
        (murdoch task rank))

(define robots '(r1 r2 r3 r4 r5 r6))

;; A turn of rank n, claiming a few robots, or the whole lab (#f) now
;; and then.
(define (random-turn n)
  (make-try-turn (make-waiter #f '() (list 0 n (number->string n)))
                 (and (> (random-integer 8) 0)
                      (filter (lambda (r) (= 0 (random-integer 3))) robots))
                 #f))

(define (rank-of t) (waiter-rank (try-turn-waiter t)))

(define (share? a b)
  (let ((x (try-turn-claim a)) (y (try-turn-claim b)))
    (or (not x) (not y) (and (any (lambda (r) (memq r y)) x) #t))))

;; Each entry: (RUNNING WAITING LET-IN) after one step.
(define (steps seed n)
  (random-source-pseudo-randomize! default-random-source seed 7)
  (let loop ((i 0) (running '()) (waiting '()) (out '()))
    (if (= i n)
        (reverse out)
        (let*-values (((joins?) (or (null? running) (< (random-integer 3) 2)))
                      ((running waiting)
                       (if joins?
                           (values running (in-try-order (random-turn i) waiting))
                           (values (remove (lambda (t) (eq? t (car running))) running)
                                   waiting)))
                      ((in left) (let-in waiting running)))
          (loop (+ i 1) (append in running) left
                (cons (list (append in running) left in waiting) out))))))

(define (none-share? ts)
  (let loop ((ts ts))
    (or (null? ts)
        (and (not (any (lambda (t) (share? (car ts) t)) (cdr ts)))
             (loop (cdr ts))))))

(test-begin "try-turn")

(for-each
 (lambda (seed)
   (let ((run (steps seed 200)))
     (test (string-append "seed " (number->string seed) ": no two running share a robot")
           #t (every (lambda (s) (none-share? (car s))) run))
     (test (string-append "seed " (number->string seed) ": none waits that could run")
           #t (every (lambda (s)
                       (let ((running (car s)) (waiting (cadr s)))
                         (every (lambda (t)
                                  (or (any (lambda (r) (share? t r)) running)
                                      (any (lambda (b) (and (share? t b)
                                                            (rank<? (rank-of b) (rank-of t))))
                                           waiting)))
                                waiting)))
                     run))
     (test (string-append "seed " (number->string seed) ": none passes a better one")
           #t (every (lambda (s)
                       (every (lambda (t)
                                (not (any (lambda (b) (and (share? t b)
                                                           (rank<? (rank-of b) (rank-of t))))
                                          (cadr s))))
                              (list-ref s 2)))
                     run))
     (test (string-append "seed " (number->string seed) ": every one runs in the end")
           '()
           (let drain ((running (car (last run))) (waiting (cadr (last run))) (n 0))
             (if (or (null? running) (> n 1000))
                 waiting
                 (let-values (((in left) (let-in waiting (cdr running))))
                   (drain (append in (cdr running)) left (+ n 1))))))))
 '(1 2 3 4 5))

(test "apart, two run at once" 2
      (let-values (((in left)
                    (let-in (list (make-try-turn (make-waiter #f '() '(0 1 "a")) '(r1) #f)
                                  (make-try-turn (make-waiter #f '() '(0 2 "b")) '(r2) #f))
                            '())))
        (length in)))

(test "the whole lab's waits for those running" 0
      (let-values (((in left)
                    (let-in (list (make-try-turn (make-waiter #f '() '(0 2 "b")) #f #f))
                            (list (make-try-turn (make-waiter #f '() '(0 1 "a")) '(r1) #f)))))
        (length in)))

(test-end)
