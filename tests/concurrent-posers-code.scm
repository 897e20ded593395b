;;; The lab code of tests/concurrent-posers-test.scm and bench/alloc.scm:
;;; components that hold their robot a moment and say so, and the tasks
;;; that the posers pose.

;; What ran here, in order: (start task) and (end task).
(define runs '())
(define (note! what) (set! runs (cons what runs)))
(define (robot-runs) (reverse runs))
;; A component: holds its robot a moment, saying when it starts and ends.
(define (hold task)
  (note! (list 'start task))
  (thread-sleep! 0.3)
  (note! (list 'end task))
  (local-aspace-uid))
;; A task of two components that want an arm each, the first ranking
;; its candidates by measure.
(define (two-arms task measure)
  (pose-task task 2 (list '((arm) ()) '((arm) ()))
             (list (metric-by measure) #f)
             (list (lambda () (hold task)) (lambda () (hold task)))))
(define (two-grips task)
  (pose-task task 2 (list '((grip) ()) '((grip) ())) (list #f #f)
             (list (lambda () (hold task)) (lambda () (hold task)))))
;; A measure that answers once a pose negotiating here has heard of a
;; rival, or after 20 s: it keeps its robots reserved until then.
(define (until-a-rival uid)
  (let loop ((n 0))
    (if (or (= n 400) (any (lambda (pose) (pair? (cddr pose))) (pose-negotiations)))
        0
        (begin (thread-sleep! 0.05) (loop (+ n 1))))))

