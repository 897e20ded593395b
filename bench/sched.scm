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
;;;   bench: sched-deadlocks N          stalls of 2 s with tasks waiting
;;;                                     and no component running
;;;   bench: sched-priority-inversions N   tasks that started while a
;;;                                     better-ranked one waited (see
;;;                                     inversions below); each is told on
;;;                                     standard error
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
        (srfi 1) (srfi 18) (srfi 27) (srfi 132)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness))

(define seed
  (cond ((get-environment-variable "MURDOCH_SCHED_SEED") => string->number)
        (else 30)))
(define robots '(r1 r2 r3 r4 r5 r6 r7 r8))
(define posers '(p1 p2 p3))
(define aging 0.1)

(define lab-code "
;; Run here, on the bench's address space, with clock set to its clock.
(define clock #f)
(define events '())                     ; (time kind id k uid), newest first
(define (note! kind id k uid)
  (set! events (cons (list (clock) kind id k uid) events)))
;; A component: a timed wait on its robot, told to bench as it starts and ends.
(define (bench-work id k seconds)
  (let ((me (local-aspace-uid)))
    (remote-apply (uid->aspace 'bench) (lambda () (note! 'start id k me)))
    (thread-sleep! seconds)
    (remote-apply (uid->aspace 'bench) (lambda () (note! 'end id k me)))
    me))
;; Run on the posers.
(define posed '())                      ; (id . task)
(define (pose-bench! id n seconds priority)
  (set! posed
        (cons (cons id
                    (start-task 'bench n (make-list n '((arm) ())) (make-list n #f)
                                (map (lambda (k) (lambda () (bench-work id k seconds)))
                                     (iota n 1))
                                'wait #t 'hold #t 'priority priority))
              posed))
  #t)
(define (bench-results)
  (map (lambda (p) (list (car p) (task-wait (cdr p) 600))) posed))
")

(define lab
  (make-test-lab
   `((code "code.scm") (aging ,aging) (max-waiting 200) (heartbeat 0.5)
     (aspace bench)
     ,@(map (lambda (uid) `(aspace ,uid)) posers)
     ,@(map (lambda (uid) `(aspace ,uid (capabilities arm))) robots))
   `(("code.scm" . ,lab-code))))

(define pids (map (lambda (uid) (cons uid (start-lab-aspace! lab uid)))
                  (append posers robots)))
(join-lab (test-lab-file lab) 'bench)
(wait-until 20 (lambda () (every (lambda (u) (memq u (live-uids)))
                                 (append posers robots))))
(define (lab-proc name) (eval name (lab-environment)))
(eval (list 'set! 'clock current-second) (lab-environment))

;;; The tasks

(define random-source (make-random-source))
(random-source-pseudo-randomize! random-source seed 0)
(define random-real (random-source-make-reals random-source))
(define (random-below n) (exact (floor (* n (random-real)))))

;; (id robots seconds priority gap): gap, seconds after the task before.
(define tasks
  (map (lambda (id)
         (let* ((r (random-real))
                (n (cond ((< r 0.7) 1) ((< r 0.9) 2) (else 3))))
           (list id n (+ 1 (* 5 (random-real))) (random-below 4)
                 (if (< id 40) 0 (* -0.6 (log (- 1 (random-real))))))))
       (iota 120)))

(define task-robots cadr)
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
                  (remote-apply (uid->aspace p) (lab-proc 'bench-results))))
              posers))

(define events
  (map (lambda (e) (cons (- (car e) t0) (cdr e)))
       (reverse (remote-apply (uid->aspace 'bench)
                              (eval '(lambda () events) (lab-environment))))))

(define (ok? result) (and (list? result) (every symbol? result)))
(define completed (count (lambda (r) (ok? (cadr r))) results))

;;; What happened

(define (events-of kind) (filter (lambda (e) (eq? (cadr e) kind)) events))
(define starts (events-of 'start))
(define ends (events-of 'end))

;; (id start end) for each task whose components all started and ended.
(define spans
  (filter-map
   (lambda (t)
     (let ((s (filter (lambda (e) (= (list-ref e 2) (car t))) starts))
           (e (filter (lambda (e) (= (list-ref e 2) (car t))) ends)))
       (and (= (length s) (task-robots t)) (= (length e) (task-robots t))
            (list (car t) (apply min (map car s)) (apply max (map car e))))))
   tasks))

(define (span-of id) (assv id spans))

;; The last release among the robots that task span sp started on, before
;; it started, or #f when none of them had run anything before.
(define (ready-at sp)
  (let ((releases
         (filter-map
          (lambda (s)
            (let ((before (filter (lambda (e) (and (eq? (list-ref e 4) (list-ref s 4))
                                                   (<= (car e) (cadr sp))))
                                  ends)))
              (and (pair? before) (apply max (map car before)))))
          (filter (lambda (s) (= (list-ref s 2) (car sp))) starts))))
    (and (pair? releases) (apply max releases))))
(define (work-of t) (let ((s (span-of (car t)))) (and s (- (car (cddr s)) (cadr s)))))

(define (del uid alist) (remove (lambda (x) (eq? (car x) uid)) alist))

;; Two components on one robot at once, seen by their starts and ends.
(define double-bookings
  (let loop ((es events) (inside '()) (n 0))
    (if (null? es)
        n
        (let* ((e (car es)) (uid (list-ref e 4)) (k (or (assq uid inside) (cons uid 0))))
          (if (eq? (cadr e) 'start)
              (loop (cdr es) (cons (cons uid (+ (cdr k) 1)) (del uid inside))
                    (if (> (cdr k) 0) (+ n 1) n))
              (loop (cdr es) (cons (cons uid (- (cdr k) 1)) (del uid inside)) n))))))

(define (rank-key t)
  (- (task-priority t) (* aging (vector-ref posed-at (car t)))))
(define (ranks-before? a b)
  (or (> (rank-key a) (rank-key b))
      (and (= (rank-key a) (rank-key b))
           (< (vector-ref posed-at (car a)) (vector-ref posed-at (car b))))))

;; Whether a ranks before b whatever second within its posing call each
;; was ranked by: a near tie that the calls' own times could turn either
;; way is no inversion.
(define (surely-ranks-before? a b)
  (let ((key (lambda (t posed)
              (- (task-priority t) (* aging (vector-ref posed (car t)))))))
    (or (> (key a posed-by) (key b posed-at))
        (and (= (task-priority a) (task-priority b))
             (< (vector-ref posed-by (car a)) (vector-ref posed-at (car b)))))))

;; The inversions: a task x starting while y, which surely ranks before
;; it, waited for a robot.  y waited from 0.2 s after its posing call
;; until the last of the robots it started on was released, if that was
;; after x started, and it had not started 0.2 s after x: a task that
;; has won its robots takes a moment to tell this address space it
;; started, and one whose robots were all free when x started was being
;; served, and needed none more.  Every task here holds what it wins,
;; and any robot serves any task, so a task that waits for a robot could
;; have used any robot freed, if only to hold it.  (x y) for each x and
;; the best-ranked such y.
(define (waited-for-robot? y sx)
  (let ((sy (span-of (car y))))
    (and (< (+ (vector-ref posed-by (car y)) 0.2) sx)
         (or (not sy)
             (and (> (cadr sy) (+ sx 0.2))
                  (> (or (ready-at sy) 0) sx))))))

(define inversions
  (filter-map
   (lambda (x)
     (let* ((sx (span-of (car x)))
            (ys (filter (lambda (y)
                          (and sx (surely-ranks-before? y x)
                               (waited-for-robot? y (cadr sx))))
                        tasks)))
       (and (pair? ys) (list x (car (list-sort ranks-before? ys))))))
   tasks))

;; Each inversion, on standard error, so that a run's can be looked into.
(define (tell-inversion! xy)
  (let ((out (current-error-port)) (x (car xy)) (y (cadr xy)))
    (define (task-line t)
      (let ((s (span-of (car t))))
        (string-append "task " (number->string (car t)) " of priority "
                       (number->string (task-priority t)) ", posed at "
                       (number->string (round-to (vector-ref posed-at (car t)) 3))
                       " s, started at "
                       (if s
                           (string-append (number->string (round-to (cadr s) 3)) " s")
                           "never"))))
    (write-string (string-append "sched: inversion: " (task-line x) "\n"
                                 "  while this better-ranked one waited: "
                                 (task-line y) "\n")
                  out)))

(define makespan (apply max 0 (map car ends)))
(define (one-robot-start? s) (= 1 (task-robots (list-ref tasks (list-ref s 2)))))

;; Stalls: 2 s or more with a task posed and not started, and no
;; component running.
(define deadlocks
  (let loop ((t 0) (quiet 0) (n 0))
    (if (> t makespan)
        n
        (let* ((waiting (any (lambda (x) (and (< (vector-ref posed-at (car x)) t)
                                              (let ((s (span-of (car x))))
                                                (or (not s) (> (cadr s) t)))))
                             tasks))
               (running (any (lambda (s) (and (<= (cadr s) t) (< t (car (cddr s)))))
                             spans))
               (quiet (if (and waiting (not running)) (+ quiet 0.1) 0)))
          (loop (+ t 0.1) quiet (if (and (>= quiet 2) (< quiet 2.1)) (+ n 1) n))))))

;; From each end on a robot to the next start there, while a task waited;
;; and the same where that start is of a one-robot task, which no task
;; could have held for a while before it started.
(define (latencies-where ok?)
  (filter-map
   (lambda (e)
     (let ((next (find (lambda (s) (and (eq? (list-ref s 4) (list-ref e 4))
                                        (>= (car s) (car e))))
                       starts)))
       (and next (ok? next)
            (any (lambda (x) (and (< (vector-ref posed-at (car x)) (car e))
                                  (let ((s (span-of (car x))))
                                    (and s (>= (cadr s) (car e))))))
                 tasks)
            (* 1000 (- (car next) (car e))))))
   ends))
(define latencies (latencies-where (lambda (s) #t)))
(define one-robot-latencies (latencies-where one-robot-start?))

;; From the last release among the robots a task starts on to its start,
;; for a task posed before that release: what the turns add, without the
;; time its other robots were held for it before, which 'hold means.
(define last-release-latencies
  (filter-map
   (lambda (sp)
     (let ((last (ready-at sp)))
       (and last (< (vector-ref posed-at (car sp)) last)
            (* 1000 (- (cadr sp) last)))))
   spans))

;;; The ideal schedule: the same arrivals and rank rule, the measured
;;; work, no messages.  At each moment the waiting tasks, best rank
;;; first, each take free robots, keeping them until they have all they
;;; need, as 'hold does; a robot taken is the one free longest.  Answers
;;; its makespan, and the start latency as the run's is measured: from a
;;; robot's release while a task waits to the next start on it.

(define (posed t) (vector-ref posed-at (car t)))

(define (ideal-schedule)
  ;; pool: (released . waited?) of each robot not running; running:
  ;; (end . robots); done: the ids of the tasks started.
  (let loop ((now 0) (pool (make-list (length robots) (cons 0 #f))) (running '())
             (done '()) (last 0) (latencies '()))
    (let fill ((ws (list-sort ranks-before?
                              (filter (lambda (t) (and (work-of t) (<= (posed t) now)
                                                       (not (memv (car t) done))))
                                      tasks)))
               (free (list-sort (lambda (a b) (< (car a) (car b))) pool))
               (held '()) (started '()) (latencies latencies))
      (cond
       ((and (pair? ws) (<= (task-robots (car ws)) (length free)))
        (let ((taken (take free (task-robots (car ws)))))
          (fill (cdr ws) (drop free (length taken)) held (cons (car ws) started)
                (append (filter-map (lambda (r) (and (cdr r) (* 1000 (- now (car r)))))
                                    taken)
                        latencies))))
       ((pair? ws) (fill (cdr ws) '() (append free held) started latencies))
       (else
        (let* ((running (append (map (lambda (t)
                                       (cons (+ now (work-of t)) (task-robots t)))
                                     started)
                                running))
               (done (append (map car started) done))
               (later (filter (lambda (x) (> x now))
                              (map (lambda (t) (vector-ref posed-at (car t)))
                                   (filter work-of tasks))))
               (next (and (or (pair? running) (pair? later))
                          (apply min (append (map car running) later)))))
          (if (not next)
              (list last latencies)
              (let* ((ended (filter (lambda (r) (<= (car r) next)) running))
                     (waited? (any (lambda (t) (and (work-of t) (not (memv (car t) done))
                                                    (< (posed t) next)))
                                   tasks)))
                (loop next
                      (append free held
                              (append-map (lambda (r)
                                            (make-list (cdr r) (cons (car r) waited?)))
                                          ended))
                      (remove (lambda (r) (<= (car r) next)) running) done
                      (apply max last (map car ended)) latencies)))))))))

(define (percentile xs p)
  (if (null? xs)
      0
      (let ((v (list->vector (list-sort < xs))))
        (vector-ref v (min (- (vector-length v) 1)
                           (exact (floor (* p (vector-length v)))))))))

(define (round-to x places)
  (let ((m (expt 10 places))) (/ (round (* x m)) m)))

(define (bench name value unit)
  (display "bench: ") (display name) (display " ") (display value)
  (display " ") (display unit) (newline))

(define robot-seconds
  (apply + (map (lambda (t) (* (task-robots t) (or (work-of t) 0))) tasks)))
(define bound (max (/ robot-seconds (length robots))
                   (apply max 0 (filter-map work-of tasks))))
(define ideal-run (ideal-schedule))
(define ideal (car ideal-run))

(bench "sched-tasks" (length tasks) "")
(bench "sched-completed" completed "")
(bench "sched-lost" (- (length tasks) completed) "")
(bench "sched-double-bookings" double-bookings "")
(bench "sched-deadlocks" deadlocks "")
(for-each tell-inversion! inversions)
(bench "sched-priority-inversions" (length inversions) "")
(bench "sched-makespan" (round-to makespan 2) "s")
(bench "sched-ideal-makespan" (round-to ideal 2) "s")
(bench "sched-makespan-over-ideal" (round-to (/ makespan ideal) 3) "x")
(bench "sched-lower-bound" (round-to bound 2) "s")
(bench "sched-makespan-over-bound" (round-to (/ makespan bound) 3) "x")
(bench "sched-start-latency-p50" (round-to (percentile latencies 0.5) 1) "ms")
(bench "sched-start-latency-p95" (round-to (percentile latencies 0.95) 1) "ms")
(bench "sched-ideal-start-latency-p50"
       (round-to (percentile (cadr ideal-run) 0.5) 1) "ms")
(bench "sched-ideal-start-latency-p95"
       (round-to (percentile (cadr ideal-run) 0.95) 1) "ms")
(bench "sched-start-latency-one-robot-p50"
       (round-to (percentile one-robot-latencies 0.5) 1) "ms")
(bench "sched-start-latency-one-robot-p95"
       (round-to (percentile one-robot-latencies 0.95) 1) "ms")
(bench "sched-start-latency-last-release-p50"
       (round-to (percentile last-release-latencies 0.5) 1) "ms")
(bench "sched-start-latency-last-release-p95"
       (round-to (percentile last-release-latencies 0.95) 1) "ms")
(bench "sched-utilization"
       (round-to (* 100 (/ robot-seconds (* (length robots) makespan))) 1) "%")
(for-each (lambda (k)
            (bench (string-append "sched-wait-p95-priority-" (number->string k))
                   (round-to (percentile (filter-map (lambda (t)
                                                       (and (= (task-priority t) k)
                                                            (span-of (car t))
                                                            (- (cadr (span-of (car t)))
                                                               (posed t))))
                                                     tasks)
                                         0.95)
                             2)
                   "s"))
          '(0 1 2 3))

(stop-all-processes!)
(remove-test-lab! lab)
