;;;; Assignment: n rows (components) to distinct columns (robots) among
;;;; m >= n, at least total cost (Gerkey & Mataric, IJRR 2004: the
;;;; instantaneous single-robot-task problem, ST-SR-IA).
;;
;; A cost matrix is a vector of n rows, each a vector of m reals; +inf.0
;; marks a pair that may not be made (the robot is no candidate for the
;; component).  An assignment is a vector of n column indices.

;;; The Hungarian method

;;> The assignment of least total cost, by the Hungarian method in
;;> O(n^2 m) (Kuhn, with Jonker-Volgenant's shortest augmenting paths),
;;> exact for n <= m; #f when no assignment avoids every +inf.0 pair.
(define (assign-optimal costs)
  (let* ((n (vector-length costs))
         (m (if (zero? n) 0 (vector-length (vector-ref costs 0)))))
    (cond ((zero? n) (vector))
          ((> n m) #f)
          (else
           (let ((assignment (hungarian (finite-costs costs) n m)))
             (and (allowed? costs assignment) assignment))))))

;; The costs, inexact, each +inf.0 made the dominant cost, so the
;; arithmetic stays finite and fewer of them always cost less; each row
;; gains a column 0, never read, as the method counts from 1.
(define (finite-costs costs)
  (let ((forbidden (inexact (dominant-cost costs))))
    (vector-map (lambda (row)
                  (list->vector
                   (cons 0. (map (lambda (c)
                                   (let ((x (inexact c))) (if (< x +inf.0) x forbidden)))
                                 (vector->list row)))))
                costs)))

;;> A cost greater than the gap between the totals of any two
;;> assignments that use only the finite costs of \var{costs}.
(define (dominant-cost costs)
  (+ 1 (* 2 (vector-length costs) (largest-finite-magnitude costs))))

(define (largest-finite-magnitude costs)
  (let rows ((i 0) (largest 0.))
    (if (= i (vector-length costs))
        largest
        (let ((row (vector-ref costs i)))
          (let columns ((j 0) (largest largest))
            (if (= j (vector-length row))
                (rows (+ i 1) largest)
                (let* ((x (inexact (vector-ref row j)))
                       (magnitude (if (< x 0.) (- 0. x) x)))
                  (columns (+ j 1)
                           (if (and (< largest magnitude) (< magnitude +inf.0))
                               magnitude
                               largest)))))))))

(define (allowed? costs assignment)
  (let loop ((i 0))
    (or (= i (vector-length assignment))
        (and (finite? (vector-ref (vector-ref costs i) (vector-ref assignment i)))
             (loop (+ i 1))))))

;; Rows and columns count from 1 here, column 0 standing for the row being
;; added; u and v are the dual potentials, p(j) the row column j has
;; (0: none), way(j) the column before j on the augmenting path.
(define (hungarian a n m)
  (let ((u (make-vector (+ n 1) 0.))
        (v (make-vector (+ m 1) 0.))
        (p (make-vector (+ m 1) 0))
        (way (make-vector (+ m 1) 0)))
    (do ((i 1 (+ i 1))) ((> i n))
      (vector-set! p 0 i)
      (augment! (shortest-path! a m u v p way) p way))
    (let ((assignment (make-vector n 0)))
      (do ((j 1 (+ j 1))) ((> j m) assignment)
        (if (positive? (vector-ref p j))
            (vector-set! assignment (- (vector-ref p j) 1) (- j 1)))))))

;; Grows the tree of the row in p(0) by Dijkstra's rule, keeping the
;; potentials feasible, until it reaches a free column; answers it.
(define (shortest-path! a m u v p way)
  (let ((minv (make-vector (+ m 1) +inf.0))
        (used (make-vector (+ m 1) #f)))
    (let loop ((j0 0))
      (vector-set! used j0 #t)
      (let* ((i0 (vector-ref p j0))
             (row (vector-ref a (- i0 1)))
             (ui0 (vector-ref u i0)))
        ;; The loop of the method's O(n^2 m), without let (docs/speed.md).
        (let scan ((j 1) (delta +inf.0) (j1 0))
          (cond
           ((> j m)
            (shift-potentials! m u v p minv used delta)
            (if (zero? (vector-ref p j1)) j1 (loop j1)))
           ((vector-ref used j) (scan (+ j 1) delta j1))
           (else
            (when (< (- (- (vector-ref row j) ui0) (vector-ref v j)) (vector-ref minv j))
              (vector-set! minv j (- (- (vector-ref row j) ui0) (vector-ref v j)))
              (vector-set! way j j0))
            (if (< (vector-ref minv j) delta)
                (scan (+ j 1) (vector-ref minv j) j)
                (scan (+ j 1) delta j1)))))))))

(define (shift-potentials! m u v p minv used delta)
  (do ((j 0 (+ j 1))) ((> j m))
    (if (vector-ref used j)
        (let ((i (vector-ref p j)))
          (vector-set! u i (+ (vector-ref u i) delta))
          (vector-set! v j (- (vector-ref v j) delta)))
        (vector-set! minv j (- (vector-ref minv j) delta)))))

;; Flips the path ending at free column j0 back to column 0.
(define (augment! j0 p way)
  (let loop ((j0 j0))
    (let ((j1 (vector-ref way j0)))
      (vector-set! p j0 (vector-ref p j1))
      (if (positive? j1) (loop j1)))))

;;; The thesis's rule, on a matrix

;;> The greedy assignment of the thesis's resolve-conflicts: each row in
;;> turn takes its cheapest column not yet taken (the first of equals);
;;> #f when a row finds none that is not +inf.0.
(define (assign-greedy costs)
  (let* ((n (vector-length costs))
         (taken (make-vector (if (zero? n) 0 (vector-length (vector-ref costs 0))) #f))
         (assignment (make-vector n 0)))
    (let loop ((i 0))
      (if (= i n)
          assignment
          (let ((j (cheapest-free (vector-ref costs i) taken)))
            (and j
                 (begin (vector-set! taken j #t)
                        (vector-set! assignment i j)
                        (loop (+ i 1)))))))))

(define (cheapest-free row taken)
  (let loop ((j 0) (best #f))
    (cond ((= j (vector-length row)) best)
          ((or (vector-ref taken j) (not (finite? (vector-ref row j))))
           (loop (+ j 1) best))
          ((or (not best) (< (vector-ref row j) (vector-ref row best)))
           (loop (+ j 1) j))
          (else (loop (+ j 1) best)))))

;;> The total cost of \var{assignment} under \var{costs}.
(define (assignment-cost costs assignment)
  (let loop ((i 0) (total 0))
    (if (= i (vector-length assignment))
        total
        (loop (+ i 1)
              (+ total (vector-ref (vector-ref costs i) (vector-ref assignment i)))))))
