;;; make bench-sched: Murdoch as a scheduler (docs/tasks.md, "Tasks that
;;; wait their turn").
;;;
;;; A lab of 8 robots (workstations with the arm capability) and 3 posers
;;; (address spaces p1 to p3).  From a fixed seed, 120 tasks: mostly of one
;;; robot, some of two and some of three, each component a timed wait of 1
;;; to 6 s on its robot, priorities 0 to 3; 40 posed at once, then the
;;; rest at random arrivals.  Every task is started with 'wait #t 'hold #t
;;; by one of the posers in turn.  Each component tells this address space
;;; when it starts and ends, so that two at once on one robot are seen
;;; from inside.  Then the ideal schedule of the same tasks is computed
;;; here: the same arrivals, the same rank rule (priority less aging times
;;; the second posed, then first posed), each task taking the time its
;;; components took in the run, and no cost of messages or negotiation.
;;; It prints
;;;   bench: sched-completed N, sched-lost N
;;;   bench: sched-deadlocks N          holding cycles of 2 s: waiting
;;;                                     tasks each with a component whose
;;;                                     every robot is held by one of them
;;;   bench: sched-stalls N             2 s with tasks waiting and no
;;;                                     component running
;;;   bench: sched-priority-inversions N   robots that went to a task while
;;;                                     a better-ranked one waited with a
;;;                                     component open that accepts them
;;;                                     (bench/schedule.sld); each is told
;;;                                     on standard error
;;;   bench: sched-makespan-over-ideal X x
;;;   bench: sched-makespan-over-bound X x, over
;;;          max(sum of robots x seconds / 8, the longest task)
;;;   bench: sched-start-latency-p50 / -p95 X ms, the issue's measure: from
;;;          a robot's release to the next component starting on it, while
;;;          tasks wait.  With 'hold, the time a robot is held for a task
;;;          of several robots until its others are free is part of it:
;;;          the rank rule's doing, not the turns' cost, and so
;;;   bench: sched-ideal-start-latency-p50 / -p95 X ms, the same measure
;;;          in the ideal schedule, which holds robots alike
;;;   bench: sched-start-latency-one-robot-p50 / -p95 X ms, the run's,
;;;          where the next start is of a task of one robot
;;;   bench: sched-start-latency-last-release-p50 / -p95 X ms, from the
;;;          last release among a task's robots to its start: what the
;;;          turns cost, the held time left out
;;;   bench: sched-utilization X %
;;;   bench: sched-wait-p95-priority-K X s
;;; MURDOCH_SCHED_SEED sets the seed (default 30).
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (scheme time) (scheme process-context) (scheme inexact)
        (srfi 1) (srfi 18) (srfi 132)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness) (bench schedule))

(define seed
  (cond ((get-environment-variable "MURDOCH_SCHED_SEED") => string->number)
        (else 30)))
(define robots '(r1 r2 r3 r4 r5 r6 r7 r8))
(define posers '(p1 p2 p3))
(define aging 0.1)

(define lab-code (string-append bench-lab-code "
;; Run on the posers.
(define (pose-bench! id n seconds priority)
  (posed! id (start-task 'bench n (make-list n '((arm) ())) (make-list n #f)
                         (map (lambda (k) (lambda () (bench-work id k seconds)))
                              (iota n 1))
                         'wait #t 'hold #t 'priority priority))
  #t)
"))

(define lab
  (make-test-lab
   `((code "code.scm") (aging ,aging) (max-waiting 200) (heartbeat 0.5)
     (aspace bench)
     ,@(map (lambda (uid) `(aspace ,uid)) posers)
     ,@(map (lambda (uid) `(aspace ,uid (capabilities arm))) robots))
   `(("code.scm" . ,lab-code))))

(start-bench-lab! lab (append posers robots) 20)

;;; The tasks

(define random-real (seeded-reals seed))
(define (random-below n) (below random-real n))

;; (id kinds seconds priority gap), as (bench schedule) reads it: a list
;; (arm) a robot; gap, seconds after the task before.
(define tasks
  (map (lambda (id)
         (let* ((r (random-real))
                (n (cond ((< r 0.7) 1) ((< r 0.9) 2) (else 3))))
           (list id (make-list n '(arm)) (+ 1 (* 5 (random-real))) (random-below 4)
                 (if (< id 40) 0 (* -0.6 (log (- 1 (random-real))))))))
       (iota 120)))

(define (task-robots t) (length (cadr t)))
(define (task-priority t) (list-ref t 3))

;;; The run

;; A task's rank is read from its poser's clock, between the two seconds
;; noted here as it is posed: before the call that poses it, and after.
(define posed-at (make-vector 120 #f))
(define posed-by (make-vector 120 #f))
(define t0 (current-second))

(for-each (lambda (t)
            (if (> (list-ref t 4) 0) (thread-sleep! (list-ref t 4)))
            (vector-set! posed-at (car t) (- (current-second) t0))
            (remote-apply (uid->aspace (list-ref posers (modulo (car t) 3)))
                          (lab-proc 'pose-bench!) (car t) (task-robots t)
                          (list-ref t 2) (task-priority t))
            (vector-set! posed-by (car t) (- (current-second) t0)))
          tasks)

(define results
  (append-map (lambda (p)
                (parameterize ((remote-timeout 900))
                  (remote-apply (uid->aspace p) (lab-proc 'bench-results) 600)))
              posers))

(define (ok? result) (and (list? result) (every symbol? result)))

(define run (make-schedule-run tasks posed-at posed-by (bench-told 'events t0)
                               (bench-told 'holdings t0)
                               (map (lambda (uid) (cons uid 'arm)) robots) aging))
(schedule-completed! run (count (lambda (r) (ok? (cadr r))) results))
(print-schedule-figures run "sched")

(stop-all-processes!)
(remove-test-lab! lab)
