;;;; Metrics (thesis §4.2, appendix A.7): how a component ranks its
;;;; candidates.

;; A metric answers #t when its first candidate, a (uid promise-or-result)
;; entry, is better, as in the thesis.  Those made here also carry their
;; keys (a measure with its tolerance, or a comparator), so pose-task asks
;; each candidate once per measure, not once per comparison, and optimal
;; assignment has numbers to add up.
(define-record-type asking
  (make-asking proc score)
  asking?
  (proc asking-proc)
  (score asking-score))

(define-record-type measure-key
  (make-measure-key measure tolerance)
  measure-key?
  (measure measure-key-measure)
  (tolerance measure-key-tolerance))

(define (keyed-metric keys)
  (lambda (entry1 entry2)
    (keys-better? keys (key-values keys entry1) (key-values keys entry2))))

(define keyed-metric-code (procedure-code (keyed-metric '())))

;; The keys of metric: its own when made here; any other procedure is its
;; one comparator.
(define (metric-keys metric)
  (cond ((not (procedure? metric)) '())
        ((and (not (opcode? metric))
              (eq? (procedure-code metric) keyed-metric-code))
         (vector-ref (procedure-vars metric) 0))
        (else (list metric))))

(define (metric-measure metric)
  (let ((keys (metric-keys metric)))
    (and (= (length keys) 1) (measure-key? (car keys))
         (measure-key-measure (car keys)))))

(define (key-values keys entry)
  (map (lambda (key)
         (if (measure-key? key)
             (measure-one (measure-key-measure key) (car entry))
             entry))
       keys))

(define-syntax key-better?             ; a macro: a call a comparison (docs/speed.md)
  (syntax-rules ()
    ((_ key a b) (if (measure-key? key) (< a (- b (measure-key-tolerance key))) (key a b)))))

;; Whether values as are better than bs by the first key that does not
;; tie them.  Ties are judged pair by pair, so not transitive.
(define (keys-better? keys as bs)
  (and (pair? keys)
       (cond ((key-better? (car keys) (car as) (car bs)) #t)
             ((null? (cdr keys)) #f)
             ((key-better? (car keys) (car bs) (car as)) #f)
             (else (keys-better? (cdr keys) (cdr as) (cdr bs))))))

;;> A metric that prefers the candidate with the smaller
;;> \scheme{(measure uid)}: a number for a candidate's uid.
(define (metric-by measure)
  (made-by! (keyed-metric (list (make-measure-key measure 0))) 'metric-by measure))

;;> A metric that prefers the candidate whose answer to \var{proc},
;;> applied there, has the smaller \scheme{(score answer)}.  pose-task
;;> asks all of a component's candidates with one message each.
(define (metric-by-asking proc score)
  (made-by! (metric-by (make-asking proc score)) 'metric-by-asking proc score))

;;> \var{metric}, a metric by one measure (metric-by, metric-by-asking,
;;> the makers below), counting two candidates whose measures differ by
;;> at most \var{tolerance} as tied, for compose-metrics to decide.
(define (metric-within tolerance metric)
  (let ((measure (metric-measure metric)))
    (if (not (and measure (real? tolerance) (>= tolerance 0)))
        (error "metric-within: a tolerance >= 0 and a metric by one measure"
               tolerance metric))
    (made-by! (keyed-metric (list (make-measure-key measure tolerance)))
              'metric-within tolerance metric)))

;;> A metric that compares by the first of \var{metrics}; where it ties
;;> two candidates, by the next; and so on.  pose-task measures each
;;> candidate once per measure of them all; a comparator among them (a
;;> metric that is a plain procedure) ties only when it prefers neither.
(define (compose-metrics . metrics)
  (for-each (lambda (m)
              (if (not (procedure? m))
                  (error "compose-metrics: a metric is a procedure" m)))
            metrics)
  (apply made-by! (keyed-metric (append-map metric-keys metrics))
         'compose-metrics metrics))

(define (measure-one measure uid)
  (if (asking? measure)
      ((asking-score measure) (ask uid (asking-proc measure)))
      (measure uid)))

;;> The distance in mm between two reckon positions, (x y theta 0).
(define (reckon-distance-between p q)
  (let ((dx (- (car p) (car q))) (dy (- (cadr p) (cadr q))))
    (sqrt (+ (* dx dx) (* dy dy)))))

(define (ask uid proc)
  (remote-apply (uid->aspace uid) proc))

;;> Prefers the candidate closest to \var{target}, (x y theta 0) as reckon
;;> answers, by each candidate's safe-reckon.
(define (location-metric-maker target)
  (made-by! (metric-by-asking safe-reckon
                              (lambda (position)
                                (reckon-distance-between target position)))
            'location-metric-maker target))

;;> Prefers the candidate with the lowest system load.
(define (load-metric-maker)
  (made-by! (metric-by-asking get-system-load string->number) 'load-metric-maker))

;;> The load metric of Figure 4.6.
(define load-metric (load-metric-maker))

;;> The opposite preference: the worst candidate by \var{metric} first,
;;> ties as they were.
(define (reverse-metric metric)
  (made-by! (keyed-metric (map reverse-key (metric-keys metric))) 'reverse-metric metric))

(define (reverse-key key)
  (if (measure-key? key)
      (make-measure-key (negated (measure-key-measure key))
                        (measure-key-tolerance key))
      (lambda (a b) (key b a))))

(define (negated measure)
  (if (asking? measure)
      (let ((score (asking-score measure)))
        (make-asking (asking-proc measure) (lambda (a) (- (score a)))))
      (lambda (uid) (- (measure uid)))))

;;> Sorts a component's candidates by its metric, best first; no metric:
;;> at random.
(define (sort-response response metric)
  (let ((keys (metric-keys metric)))
    (map cdr (sort-measured (measured-response response keys) keys))))

;; Each candidate as (values . entry), each measure asked of every
;; candidate once; asked holds answers already had (request-components).
(define (measured-response response keys . asked)
  (with-values response (key-columns response keys (and (pair? asked) (car asked)))))

(define (with-values response columns)  ; not (apply map ...): docs/speed.md
  (if (null? response)
      '()
      (cons (cons (firsts columns) (car response))
            (with-values (cdr response) (rests columns)))))

(define (firsts ls) (if (null? ls) '() (cons (caar ls) (firsts (cdr ls)))))
(define (rests ls) (if (null? ls) '() (cons (cdar ls) (rests (cdr ls)))))

(define (key-columns response keys asked)
  (let loop ((keys keys) (k 0))
    (if (null? keys)
        '()
        (let ((measure (and (measure-key? (car keys))
                            (measure-key-measure (car keys)))))
          (cond ((not measure) (cons response (loop (cdr keys) k)))
                ((and asked (asking? measure))
                 (cons (measured-told response
                                      (map-guarded (lambda (e) (asked-score measure asked e k))
                                                   response unscored))
                       (loop (cdr keys) (+ k 1))))
                (else
                 (cons (measured-told response (measure-all measure (map car response)))
                       (loop (cdr keys) k))))))))

;; Candidate entry's score by an asking measure from its k-th answer.
(define (asked-score measure asked entry k)
  (answer-score measure (nth-pair (assq (car entry) asked) (+ k 1))))

(define (nth-pair ls i) (and (list? ls) (tail-at ls i))) ; the i-th's, or #f

(define (tail-at ls i)                  ; not length and list-ref: a call a step
  (cond ((not (pair? ls)) #f)
        ((eq? i 0) ls)
        (else (tail-at (cdr ls) (- i 1)))))

(define (answer-score measure p)
  (if (and p (list? (car p)))
      (score measure (asked-ok? (car p)) (and (pair? (cdar p)) (asked-value (car p))))
      +inf.0))

(define (measured-told response measures)
  (progress "  measured " (map list (map car response) measures))
  measures)

;; The procedures a candidate is asked for the measures among keys.
(define (asking-procs keys)
  (filter-map (lambda (key)
                (and (measure-key? key) (asking? (measure-key-measure key))
                     (asking-proc (measure-key-measure key))))
              keys))

(define (sort-measured measured keys)
  (if (null? keys)
      (shuffle measured)
      (list-sort (lambda (a b) (keys-better? keys (car a) (car b))) measured)))

;; Measures every candidate at once; one that cannot be measured scores
;; +inf.0, and so comes last.
(define (measure-all measure uids)
  (if (asking? measure)
      (map-guarded (lambda (o)
                     (score measure (outcome-ok? o) (and (outcome-ok? o) (outcome-value o))))
                   (remote-apply-all (map uid->aspace uids) (asking-proc measure))
                   unscored)
      (map thread-join!
           (map (lambda (uid)
                  (thread-start!
                   (make-thread (lambda () (guard (e (#t +inf.0)) (measure uid))))))
                uids))))

;; An asking measure's score of an answer, or +inf.0; the score is user
;; code and may raise.
(define (score measure ok? answer)
  (let ((score (and ok? ((asking-score measure) answer))))
    (if (real? score) score +inf.0)))

(define (unscored candidate e) +inf.0)

(define (shuffle ls)
  (map cdr (list-sort (lambda (a b) (< (car a) (car b)))
                      (map (lambda (x) (cons (random-real) x)) ls))))
