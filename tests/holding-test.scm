;;; The matching of offered robots to a waiting task's open components
;;; (lib/murdoch/task/rank.scm): offered-enough? declines a robot that
;;; adds nothing to it, and hold-try gives each component the robot it
;;; matches, so that a robot only one component can use is not taken by
;;; another.  Checked against an exhaustive count on generated cases.
(import (scheme base) (srfi 1) (chibi test)
        (only (murdoch task record) make-component component-index)
        (murdoch task rank))

;; A waiting task whose components, one per entry of capables, fit the
;; robots listed, or any robot where the entry is #t; held, the indices
;; of those it holds.
(define (waiter-of capables . held)
  (let* ((cs (map (lambda (i) (make-component i '((arm) ()) #f #f #f))
                  (iota (length capables) 1)))
         (w (make-waiter #f cs 0)))
    (waiter-held-set! w (map (lambda (i) (list i #f 'exclusive)) held))
    (waiter-capables-set! w (filter-map (lambda (c uids) (and (list? uids) (cons c uids)))
                                        cs capables))
    w))

;; The robot each open component takes once uids are matched in turn, or
;; #f: of all matched (to others than no component), the one not matched
;; to the others.
(define (taken-after w uids)
  (let ((m (open-matching w (waiter-components w))))
    (for-each (lambda (uid) (match! m uid)) uids)
    (map (lambda (c)
           (let ((others (matched-to-others m c)))
             (find (lambda (uid) (not (memq uid others))) (matched-to-others m #f))))
         (remove (lambda (c) (assv (component-index c) (waiter-held w)))
                 (waiter-components w)))))

(test-begin "holding")

(test-group "a robot goes where no other can"
  ;; ra fits the first only; rb fits both.  rb, matched first, is moved
  ;; on to the second when ra comes.
  (let ((w (waiter-of '((ra rb) (rb)))))
    (test "each component its own robot" '(ra rb) (taken-after w '(rb ra))))
  (let* ((w (waiter-of '((ra rb) (rb))))
         (m (open-matching w (waiter-components w))))
    (test "rb matches" #t (match! m 'rb))
    (test "ra matches, moving rb on" #t (match! m 'ra))
    (test "rc adds nothing: enough were offered" #f (match! m 'rc))
    (test "the first is given ra, the second rb"
      '((rb) (ra))
      (map (lambda (c) (matched-to-others m c)) (waiter-components w)))))

(test-group "held components are left out, and a component known to no look fits any"
  (let* ((w (waiter-of '((ra) #t) 1))
         (m (open-matching w (waiter-components w))))
    (test "rc fits the second, the one open" #t (match! m 'rc))
    (test "and rd adds nothing: one is open" #f (match! m 'rd))))

(test-group "the order given is the order preferred"
  (let* ((w (waiter-of '((ra rb) (ra rb))))
         (cs (waiter-components w))
         (m (open-matching w (reverse cs))))
    (match! m 'ra)
    (test "ra goes to the first in order, the second component"
      '((ra) ())
      (map (lambda (c) (matched-to-others m c)) cs))))

;; The most components robots could take, one each, by trying every
;; assignment: the count the matching must reach.
(define (most-matched capables uids)
  (let best ((cs capables) (free uids))
    (if (null? cs)
        0
        (max (best (cdr cs) free)
             (fold (lambda (uid n)
                     (if (or (eq? (car cs) #t) (memq uid (car cs)))
                         (max n (+ 1 (best (cdr cs) (delete uid free))))
                         n))
                   0 free)))))

(define seed 46)
(define (random-below n)
  (set! seed (modulo (+ (* seed 1103515245) 12345) 2147483648))
  (modulo (quotient seed 65536) n))

(define robots '(r1 r2 r3 r4 r5))

(define (random-capables)
  (map (lambda (i)
         (if (= 0 (random-below 6))
             #t
             (filter (lambda (r) (= 0 (random-below 2))) robots)))
       (iota (+ 1 (random-below 4)))))

(test-group "on 300 generated cases, as many components as an exhaustive count"
  (test "none differs" '()
    (let loop ((k 0) (bad '()))
      (if (= k 300)
          bad
          (let* ((capables (random-capables))
                 (uids (filter (lambda (r) (= 0 (random-below 2))) robots))
                 (w (waiter-of capables))
                 (m (open-matching w (waiter-components w)))
                 (n (count (lambda (uid) (match! m uid)) uids)))
            (loop (+ k 1)
                  (if (= n (most-matched capables uids))
                      bad
                      (cons (list capables uids n) bad))))))))

(test-group "before a look, a robot matched by guess is kept from no component"
  ;; Neither component is known to a look: ra goes to the first by guess,
  ;; and the second's negotiation may still take it, where it may fit.
  (let* ((w (waiter-of '(#t #t)))
         (m (open-matching w (waiter-components w))))
    (match! m 'ra)
    (test "ra is left to both" '(() ())
      (map (lambda (c) (matched-to-others m c)) (waiter-components w)))))

(test-group "a robot is offered only for a component not held"
  ;; Before its look, a task holding its arm component wants a robot
  ;; subscribed to lift, not one subscribed to arm alone.
  (let* ((cs (list (make-component 1 '((arm) ()) #f #f #f)
                   (make-component 2 '((lift) ()) #f #f #f)))
         (w (make-waiter #f cs 0)))
    (waiter-capable-set! w #t)
    (waiter-held-set! w (list (list 1 #f 'exclusive)))
    (test "not an arm" #f (wants? w 'r1 '(arm)))
    (test-assert "a lift" (wants? w 'r2 '(lift)))))

(test-group "before a look, a robot whose subjects are known fits by them"
  (let* ((cs (list (make-component 1 '((arm) ()) #f #f #f)
                   (make-component 2 '((lift) ()) #f #f #f)))
         (w (make-waiter #f cs 0))
         (m (begin (waiter-held-set! w '()) (open-matching w cs))))
    (note-subjects! 'lifter '(lift))
    (note-subjects! 'camera '(camera))
    (test "a robot that fits none adds nothing" #f (match! m 'camera))
    (test "the lifter goes to the lift component" #t (match! m 'lifter))
    (test "and is kept from the arm's negotiation only once a look knows it"
      '(() ())
      (map (lambda (c) (matched-to-others m c)) cs))
    (test "an arm it never heard of still fits the arm" #t (match! m 'stranger))))

(test-end)
