;;;; Allocation figures (docs/allocation.md), by `make bench-alloc`:
;;;;   bench: assign-optimal-64x64 VALUE ms             the Hungarian method on
;;;;                                                     64 components by 64
;;;;                                                     robots, median
;;;;   bench: assign-greedy-over-optimal-mean VALUE x   the thesis's greedy
;;;;   bench: assign-greedy-over-optimal-worst VALUE x  rule's total cost over
;;;;                                                     the least, on 1,000
;;;;                                                     random problems of 4
;;;;                                                     to 16 robots
;;;;   bench: concurrent-posers-success VALUE %          three address spaces
;;;;                                                     posing a two-robot
;;;;                                                     task each at once, six
;;;;                                                     robots: the share of
;;;;                                                     tasks that got theirs
;; A random problem puts as many robots as targets at random in a 10 m
;; square, and a robot's cost for a target is its distance, as the
;; location metric measures it.

(import (except (scheme base) lambda define) (scheme write) (scheme time)
        (scheme inexact) (scheme eval) (srfi 1) (srfi 18) (srfi 27)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch task assign)
        (murdoch testing harness))

(define (random-point) (list (* 10000 (random-real)) (* 10000 (random-real))))

(define (distances n)
  (let ((targets (list-tabulate n (lambda (i) (random-point))))
        (robots (list-tabulate n (lambda (i) (random-point)))))
    (list->vector
     (map (lambda (t)
            (list->vector
             (map (lambda (r) (reckon-distance-between t r)) robots)))
          targets))))

(define (say name value unit)
  (for-each display (list "bench: " name " " value " " unit))
  (newline))

(define (rounded x places)
  (let ((k (expt 10 places))) (/ (round (* k x)) k)))

(define (bench-optimal-64)
  (let ((costs (distances 64)))
    (say "assign-optimal-64x64"
         (rounded (* 1000 (median-seconds 21 (lambda () (assign-optimal costs)))) 1)
         "ms")))

(define (bench-greedy-price)
  (let ((ratios (map (lambda (i)
                       (let ((costs (distances (+ 4 (random-integer 13)))))
                         (/ (assignment-cost costs (assign-greedy costs))
                            (assignment-cost costs (assign-optimal costs)))))
                     (iota 1000))))
    (say "assign-greedy-over-optimal-mean" (rounded (/ (apply + ratios) 1000) 3) "x")
    (say "assign-greedy-over-optimal-worst" (rounded (apply max ratios) 3) "x")))

;; The lab of tests/concurrent-posers-test.scm without its arms.
(define grippers '(g1 g2 g3 g4 g5 g6))
(define posers '(p1 p2 p3))
(define rounds 10)

(define (bench-concurrent-posers)
  (let ((lab (make-test-lab
              `((code ,(tool-path "tests/concurrent-posers-code.scm"))
                (aspace bencher)
                ,@(map (lambda (uid) `(aspace ,uid (position 0 0 0) (capabilities grip)))
                       grippers)
                ,@(map (lambda (uid) `(aspace ,uid (position 0 0 0))) posers)))))
    (for-each (lambda (uid) (start-lab-aspace! lab uid)) (append grippers posers))
    (join-lab (test-lab-file lab) 'bencher)
    (let ((got (append-map (lambda (round) (three-at-once)) (iota rounds))))
      (say "concurrent-posers-success"
           (rounded (* 100 (/ (count pair? got) (length got))) 1) "%"))
    (stop-all-processes!)
    (remove-test-lab! lab)))

;; What the three posers' tasks answered, posed at once.
(define (three-at-once)
  (let ((two-grips (eval-in-lab 'two-grips)))
    (map thread-join!
         (map (lambda (poser)
                (thread-start!
                 (make-thread
                  (lambda ()
                    (parameterize ((remote-timeout 120))
                      (remote-apply (uid->aspace poser)
                                    (lambda () (two-grips (local-aspace-uid)))))))))
              posers))))

(define (eval-in-lab name) (eval name (lab-environment)))

(bench-optimal-64)
(bench-greedy-price)
(bench-concurrent-posers)
