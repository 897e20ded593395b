;;; (murdoch task assign): the Hungarian method against every permutation, on
;;; square and rectangular problems, with pairs that may not be made; and
;;; the thesis's greedy rule where it pays more.
(import (scheme base) (srfi 1) (srfi 27) (chibi test) (murdoch task assign))

;; The least total cost over every way to give the rows distinct columns,
;; by trying them all: the answer the method must match.
(define (brute-force-cost costs)
  (let try ((i 0) (taken '()))
    (if (= i (vector-length costs))
        0
        (fold (lambda (j best)
                (if (memv j taken)
                    best
                    (min best (+ (vector-ref (vector-ref costs i) j)
                                 (try (+ i 1) (cons j taken))))))
              +inf.0
              (iota (vector-length (vector-ref costs 0)))))))

(define (random-costs n m)
  (vector-map (lambda (row) (vector-map (lambda (x) (random-integer 100)) row))
              (make-initialized n (lambda () (make-vector m 0)))))

(define (make-initialized n make)
  (let ((v (make-vector n)))
    (do ((i 0 (+ i 1))) ((= i n) v) (vector-set! v i (make)))))

(define (distinct? assignment)
  (let ((ls (vector->list assignment)))
    (= (length ls) (length (delete-duplicates ls)))))

(test-begin "assign")

;; Greedy gives row 0 its cheapest column, and row 1 is left the dear one.
(define dear '#(#(1 2) #(2 100)))
(test "greedy takes the cheapest first" '#(0 1) (assign-greedy dear))
(test "and pays 101" 101 (assignment-cost dear (assign-greedy dear)))
(test "optimal gives each the other" '#(1 0) (assign-optimal dear))
(test "and pays 4" 4 (assignment-cost dear (assign-optimal dear)))

(test "more columns than rows: the cheapest pair of three" '#(2 0)
  (assign-optimal '#(#(5 4 1) #(1 3 9))))
(test "a pair that may not be made is avoided, dear as the rest is" '#(0 1)
  (assign-optimal '#(#(100 1) #(+inf.0 2))))
(test "#f when every assignment makes one" #f
  (assign-optimal '#(#(1 +inf.0) #(2 +inf.0))))
(test "#f when there are more rows than columns" #f
  (assign-optimal '#(#(1) #(2))))
(test "greedy: #f when a row finds nothing left" #f
  (assign-greedy '#(#(1 +inf.0) #(2 +inf.0))))
(test "no rows: an empty assignment" '#() (assign-optimal '#()))
(test "negative and fractional costs" '#(1 0)
  (assign-optimal '#(#(-1 -5.5) #(-2 3))))

(test "random square and rectangular problems match every permutation's best"
    '()
  (filter-map
   (lambda (k)
     (let* ((n (+ 1 (random-integer 5)))
            (costs (random-costs n (+ n (random-integer 3))))
            (a (assign-optimal costs)))
       (and (not (and (distinct? a)
                      (= (assignment-cost costs a) (brute-force-cost costs))))
            costs)))
   (iota 200)))

(test "greedy never pays less than optimal" #t
  (every (lambda (k)
           (let ((costs (random-costs 6 8)))
             (>= (assignment-cost costs (assign-greedy costs))
                 (assignment-cost costs (assign-optimal costs)))))
         (iota 50)))

(test-end)
(test-exit)
