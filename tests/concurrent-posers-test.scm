;;; Tasks posed at once from different address spaces, wanting the same
;;; robots (docs/allocation.md): with robots enough for all, all succeed;
;;; with too few, the higher priority goes first; no robot ever runs two
;;; components at once.  Workstations with a grip stand in for robots.
(import (except (scheme base) lambda define) (scheme eval)
        (srfi 1) (srfi 18) (srfi 132) (chibi test)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness))

(define grippers '(g1 g2 g3 g4 g5 g6))
(define posers '(p1 p2 p3))

(define lab
  (make-test-lab
   `((code ,(tool-path "tests/concurrent-posers-code.scm"))
     (aspace tester)
     ,@(map (lambda (uid) `(aspace ,uid (position 0 0 0) (capabilities grip)))
            grippers)
     (aspace arm1 (position 0 0 0) (capabilities arm))
     (aspace arm2 (position 0 0 0) (capabilities arm))
     ,@(map (lambda (uid) `(aspace ,uid (position 0 0 0))) posers))))

(for-each (lambda (uid) (start-lab-aspace! lab uid))
          (append grippers '(arm1 arm2) posers))
(join-lab (test-lab-file lab) 'tester)

;; The lab code's procedures, which travel by name.
(define (lab-proc name) (eval name (lab-environment)))
(define two-grips (lab-proc 'two-grips))
(define hold (lab-proc 'hold))
(define until-a-rival (lab-proc 'until-a-rival))
(define two-arms (lab-proc 'two-arms))

(define (on uid proc)
  (parameterize ((remote-timeout 120)) (remote-apply (uid->aspace uid) proc)))

;; Runs each thunk in a thread of its own, all at once; their values.
(define (at-once . thunks)
  (map thread-join! (map (lambda (t) (thread-start! (make-thread t))) thunks)))

;; uids in name order.
(define (sort-uids uids)
  (map string->symbol (list-sort string<? (map symbol->string uids))))

;; Whether, on every robot, each component ended before the next started.
(define (never-double-booked? uids)
  (every (lambda (uid)
           (let loop ((runs (on uid (lambda () (robot-runs)))))
             (or (null? runs)
                 (and (eq? (car (car runs)) 'start)
                      (equal? (cadr runs) (list 'end (cadr (car runs))))
                      (loop (cddr runs))))))
         uids))

(define (held uids subject)
  (filter-map (lambda (uid) (let ((s (on uid (lambda () (topic-status subject)))))
                              (and (symbol? s) s)))
              uids))

(define (free? uids subject)
  (every (lambda (uid) (null? (on uid (lambda () (topic-status subject))))) uids))

(test-begin "concurrent posers")

;; Three address spaces pose a two-robot task each, at once, three times
;; over; six robots are enough for all three.
(define (three-at-once round)
  (apply at-once
         (map (lambda (poser)
                (lambda ()
                  (on poser (lambda () (two-grips (local-aspace-uid))))))
              posers)))
(define results (append-map three-at-once (iota 3)))

(test "three posers at once, three times: every task gets two robots" 9
  (count (lambda (r) (and (list? r) (= 2 (length r)) (not (eq? (car r) (cadr r)))
                          (every (lambda (uid) (memq uid grippers)) r)))
         results))
(test "no robot ran two components at once" #t (never-double-booked? grippers))
(test "and afterwards every grip is free" #t (free? grippers 'grip))

;; Two tasks want both arms.  The one of lower priority is posed first,
;; and holds the arms while it measures them, until the other, of higher
;; priority, has found them held and said so.  It gives way: the higher
;; goes first, and the lower, trying again, after it.
(define low
  (make-thread
   (lambda ()
     (on 'p2 (lambda ()
               (parameterize ((pose-task-priority 0) (pose-task-retries 8))
                 (two-arms 'low until-a-rival)))))))
(thread-start! low)
(test "the lower-priority task holds both arms first" 2
  (begin (wait-until 30 (lambda () (= 2 (length (held '(arm1 arm2) 'arm)))))
         (length (held '(arm1 arm2) 'arm))))
(define high
  (on 'p1 (lambda ()
            (parameterize ((pose-task-priority 5) (pose-task-retries 8))
              (two-arms 'high (lambda (uid) 0))))))
(define low-result (thread-join! low))

(test "the higher-priority task gets both arms" '(arm1 arm2)
  (and (list? high) (sort-uids high)))
(test "and runs first on each" '((start high) (start high))
  (map (lambda (uid) (car (on uid (lambda () (robot-runs))))) '(arm1 arm2)))
(test "the lower, trying again, runs after it or gives up" #t
  (or (eq? low-result 'not-enough-takers)
      (equal? (sort-uids low-result) '(arm1 arm2))))
(test "no arm ran two components at once" #t (never-double-booked? '(arm1 arm2)))
(test "and afterwards both arms are free" #t (free? '(arm1 arm2) 'arm))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
