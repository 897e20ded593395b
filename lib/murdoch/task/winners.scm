;;;; Choosing the winners, part of (murdoch task pose-task): from the
;;;; candidates measured for each component, the robot each gets.

;; The components' winners, in component order, from their measured
;; candidates, by (pose-task-assignment); #f when some component is left
;; without a robot.
(define (choose measured keys-list priorities)
  (if (eq? (pose-task-assignment) 'optimal)
      (choose-optimally measured keys-list priorities)
      (resolve-conflicts (map sorted-entries measured keys-list) priorities)))

(define (sorted-entries measured keys)
  (map cdr (sort-measured measured keys)))

;; Components with a metric by one measure share their robots at least
;; total cost; the others pick first, by the greedy rule, among
;; themselves.
(define (choose-optimally measured keys-list priorities)
  (let* ((all (iota (length measured)))
         (optimal (filter (lambda (i) (one-measure? (list-ref keys-list i))) all))
         (greedy (remove (lambda (i) (memv i optimal)) all))
         (picks (make-vector (length measured) #f)))
    (for-each (lambda (i)
                (progress "  component " (+ i 1) " is not by one measure: greedy"))
              greedy)
    (and (fill! picks greedy
                (resolve-conflicts (map sorted-entries (pick-out measured greedy)
                                        (pick-out keys-list greedy))
                                   (pick-out priorities greedy)))
         (fill! picks optimal
                (assign-measured (map (lambda (m) (untaken m picks))
                                      (pick-out measured optimal))))
         (vector->list picks))))

(define (one-measure? keys) (and (= (length keys) 1) (measure-key? (car keys))))

(define (pick-out ls indices) (map (lambda (i) (list-ref ls i)) indices))

;; Puts chosen, a list of picks or #f, at indices of picks; true if any.
(define (fill! picks indices chosen)
  (and chosen
       (begin (for-each (lambda (i pick) (vector-set! picks i pick)) indices chosen)
              #t)))

;; The measured candidates whose robot no pick has.
(define (untaken measured picks)
  (remove (lambda (m) (find (lambda (p) (and p (eq? (car p) (cadr m))))
                            (vector->list picks)))
          measured))

;; The entries, one per list of measured candidates ((measure) uid ...),
;; of least total measure on distinct robots; #f if there is none.  A
;; candidate that could not be measured (+inf.0) costs more than any
;; assignment of measured ones, so it is chosen only when it must be.
(define (assign-measured lists)
  (let* ((uids (delete-duplicates (append-map (lambda (l) (map cadr l)) lists)))
         (costs (cost-matrix lists uids
                             (dominant-cost (cost-matrix lists uids +inf.0))))
         (assignment (assign-optimal costs)))
    (and assignment
         (let ((picks (map (lambda (l j) (assq (list-ref uids j) (map cdr l)))
                           lists (vector->list assignment))))
           (progress "  optimal assignment: total "
                     (assignment-cost costs assignment))
           picks))))

;; The components' measures of uids: +inf.0 where a uid is no candidate,
;; unmeasured where it could not be measured.
(define (cost-matrix lists uids unmeasured)
  (list->vector
   (map (lambda (measured)
          (vector-map (lambda (uid)
                        (let ((m (find (lambda (m) (eq? (cadr m) uid)) measured)))
                          (cond ((not m) +inf.0)
                                ((finite? (caar m)) (caar m))
                                (else unmeasured))))
                      (list->vector uids)))
        lists)))

;;> Takes lists of (uid ...) entries, each sorted best first, and picks
;;> for each, in order of \var{priorities} (a real for each list, the
;;> higher first; by default the lists' order, as in the thesis), the
;;> first entry whose robot no list picked before has taken; answers the
;;> picks in the lists' order, or #f if a list runs out.
(define (resolve-conflicts sorted-lists . priorities)
  (let ((picks (make-vector (length sorted-lists) #f)))
    (let loop ((order (priority-order
                       (if (pair? priorities)
                           (car priorities)
                           (thesis-priorities (length sorted-lists)))))
               (chosen '()))
      (if (null? order)
          (vector->list picks)
          (let ((pick (find (lambda (entry) (not (assq (car entry) chosen)))
                            (list-ref sorted-lists (car order)))))
            (and pick
                 (begin (vector-set! picks (car order) pick)
                        (loop (cdr order) (cons pick chosen)))))))))

;; The thesis's priorities of n components: their order, first highest.
(define (thesis-priorities n) (if (exact-integer? n) (iota n n -1) '()))

;; The indices of priorities, highest first; equals keep their order.
(define (priority-order priorities)
  (map cdr (list-sort (lambda (a b) (> (car a) (car b)))
                      (map cons priorities (iota (length priorities))))))
