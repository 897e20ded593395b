;;; make bench-sched-scale: Murdoch as a scheduler of a queue of thousands
;;; (issue 43; docs/allocation.md, "What an offer round costs").
;;;
;;; A lab of 64 robots (workstations, no motion) of 4 kinds, a to d, and 8
;;; posers.  A robot of kind a subscribes to a and to the pairs ab and da,
;;; and so on round the ring, so that a component needing (a) accepts
;;; kind a only and one needing (ab) accepts a or b; those are shared, and
;;; each robot's one exclusive subject is station: a component needs
;;; ((station) (KIND)).  Each subject is a resource of its own in pubsub,
;;; so kinds that were exclusive would let one robot run a component
;;; needing a beside one needing ab.  From a seed, 2,500
;;; tasks of 1 to 4 components, each component a timed wait of 0.2 to 2 s
;;; (the same for all of a task's), accepting one kind or two, priorities
;;; 0 to 3, every one with 'wait #t 'hold #t; 500 posed at once, then the
;;; rest at random arrivals faster than the lab serves them, so that the
;;; queue grows to about 2,000.  The posers pose in parallel, each its own
;;; tasks.  Each component tells this address space when it starts and
;;; ends, as in make bench-sched, and each poser what its waiting tasks
;;; hold as that changes; bench/schedule.sld judges the run beside its
;;; ideal schedule: the same lines as make bench-sched's, named
;;; sched-scale-.  Besides, once a second, the lab's CPU (the posers'
;;; and robots' processes) and how many tasks have started and are
;;; queued (posed, not started):
;;;   bench: sched-scale-cpu-per-start-us-at-Q X us, the lab's CPU over
;;;          the seconds when the queue held Q/sqrt(2) to Q*sqrt(2) tasks,
;;;          over the tasks started then, for Q 500 and 2000;
;;;   bench: sched-scale-posers-cpu-per-start-us-at-Q X us, the same of
;;;          the posers' CPU alone;
;;;   bench: sched-scale-cpu-per-start-growth X x, the second over the
;;;          first, beside sched-scale-log-growth, log 2000 / log 500.
;;; And the floor of a freed robot's start, in the same run: a freed robot
;;; asks the posers who waits, offers itself, is reserved and promised,
;;; runs and tells this address space, at least five calls in a row.
;;; Twice a second this one calls probe1, which calls probe2 four times,
;;; two more address spaces of the lab, idle but for this:
;;;   bench: sched-scale-floor-5-calls-p50, -p95 X ms, and
;;;   bench: sched-scale-last-release-p95-over-floor X x.
;;; Sizes: MURDOCH_SCHED_SCALE_ROBOTS (64, a multiple of 4), _POSERS (8),
;;; _TASKS (2500), _BURST (500), _GAP (mean seconds between arrivals,
;;; 0.008); MURDOCH_SCHED_SEED (30).  MURDOCH_SCHED_SCALE_SAVE=FILE writes
;;; the run to FILE, and MURDOCH_SCHED_SCALE_REPLAY=FILE judges it again,
;;; with the same sizes and seed, without a lab.
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (scheme time) (scheme process-context) (scheme inexact) (scheme file) (scheme read)
        (srfi 1) (srfi 18) (srfi 132)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness)
        (bench clock) (bench schedule))

(define (setting name default)
  (cond ((get-environment-variable name) => string->number)
        (else default)))
(define seed (setting "MURDOCH_SCHED_SEED" 30))
(define n-robots (setting "MURDOCH_SCHED_SCALE_ROBOTS" 64))
(define n-posers (setting "MURDOCH_SCHED_SCALE_POSERS" 8))
(define n-tasks (setting "MURDOCH_SCHED_SCALE_TASKS" 2500))
(define burst (setting "MURDOCH_SCHED_SCALE_BURST" 500))
(define gap (setting "MURDOCH_SCHED_SCALE_GAP" 0.008))
(define aging 0.1)

(define kinds '(a b c d))
;; Each kind's subjects: its own, and the pairs it is in round the ring.
(define pairs '((ab a b) (bc b c) (cd c d) (da d a)))
(define (subjects-of kind)
  (cons* 'station kind (filter-map (lambda (p) (and (memq kind (cdr p)) (car p))) pairs)))

(define (numbered prefix n)
  (map (lambda (i) (string->symbol (string-append prefix (number->string i))))
       (iota n 1)))
(define robots (map (lambda (uid i) (cons uid (list-ref kinds (modulo i 4))))
                    (numbered "r" n-robots) (iota n-robots)))
(define posers (numbered "p" n-posers))

(define lab-code (string-append bench-lab-code "
;; Run on the posers: subjects, one a component.
(define (pose-bench! id subjects seconds priority)
  (posed! id (start-task 'bench (length subjects)
                         (map (lambda (s) (list '(station) (list s))) subjects)
                         (map (lambda (s) #f) subjects)
                         (map (lambda (k) (lambda () (bench-work id k seconds)))
                              (iota (length subjects) 1))
                         'wait #t 'hold #t 'priority priority))
  #t)
;; Run on probe1: n calls to probe2 in a row.
(define (probe-calls n)
  (do ((i 0 (+ i 1))) ((= i n) #t) (remote-apply (uid->aspace 'probe2) (lambda () #t))))
"))

;;; The tasks

(define random-real (seeded-reals seed))
(define (random-below n) (below random-real n))

;; A component's subject: a kind, or a pair of kinds.
(define (random-subject)
  (if (< (random-real) 0.5)
      (list-ref kinds (random-below 4))
      (car (list-ref pairs (random-below 4)))))
(define (accepted subject)
  (cond ((assq subject pairs) => cdr) (else (list subject))))

;; (id subjects seconds priority at): at, the second it is posed.
(define plan
  (let loop ((id 0) (at 0) (out '()))
    (if (= id n-tasks)
        (reverse out)
        (let ((at (if (< id burst) 0 (+ at (* (- gap) (log (- 1 (random-real))))))))
          (loop (+ id 1) at
                (cons (list id (list-tabulate (+ 1 (random-below 4))
                                              (lambda (k) (random-subject)))
                            (+ 0.2 (* 1.8 (random-real))) (random-below 4) at)
                      out))))))

;;; The run

;; A task's rank is read from its poser's clock, between the two seconds
;; noted here as it is posed: before the call that poses it, and after.
;; Each poser poses its own tasks, at their seconds, in a thread of its
;; own.  Answers what the judge reads: (POSED-AT POSED-BY EVENTS HOLDINGS
;; SAMPLES COMPLETED), the seconds from the run's start.
(define (run-lab!)
  (define lab
    (make-test-lab
     ;; Every address space is on this host: the bench's and each poser's
     ;; hear from every robot, more than the 64 a host that the lab allows
     ;; by default (they refused the robots' calls, and the lab stalled).
     ;; A heartbeat of 1 s: with 73 address spaces on two cores (load
     ;; averages of 30), a poser's heartbeats to its components' robots fell
     ;; more than the two periods of 0.5 s behind, and the robots stopped
     ;; them as orphans (docs/allocation.md).
     `((code "code.scm") (aging ,aging) (max-waiting ,n-tasks) (heartbeat 1)
       (max-connections-per-host ,(* 2 (+ n-robots n-posers 1)))
       (aspace bench) (aspace probe1) (aspace probe2)
       ,@(map (lambda (uid) `(aspace ,uid)) posers)
       ,@(map (lambda (r) `(aspace ,(car r) (capabilities ,@(subjects-of (cdr r)))))
              robots))
     `(("code.scm" . ,lab-code))))
  (define uids (append posers (map car robots)))
  (define pids (take (start-bench-lab! lab (append uids '(probe1 probe2)) 60) (length uids)))
  (define posed-at (make-vector n-tasks #f))
  (define posed-by (make-vector n-tasks #f))
  (define n-posed 0)
  (define t0 (current-second))
  (define (pose-all! poser mine)
    (for-each (lambda (t)
                (let ((wait (- (list-ref t 4) (- (current-second) t0))))
                  (if (> wait 0) (thread-sleep! wait)))
                (vector-set! posed-at (car t) (- (current-second) t0))
                (parameterize ((remote-timeout 60))
                  (remote-apply (uid->aspace poser) (lab-proc 'pose-bench!) (car t)
                                (cadr t) (list-ref t 2) (list-ref t 3)))
                (vector-set! posed-by (car t) (- (current-second) t0))
                (set! n-posed (+ n-posed 1)))
              mine))
  (define samples '())
  (define sampling #t)
  (define floor-calls '())
  (define prober
    (thread-start! (make-thread (lambda ()
                                  (let loop ()
                                    (let ((t (current-second)))
                                      ;; A call refused on a loaded host
                                      ;; ("no welcome") is no figure.
                                      (guard (e (#t #f))
                                        (remote-apply (uid->aspace 'probe1) (lab-proc 'probe-calls) 4)
                                        (set! floor-calls (cons (- (current-second) t) floor-calls))))
                                    (thread-sleep! 0.5)
                                    (if sampling (loop)))))))
  (define sampler
    (thread-start! (make-thread (lambda ()
                                  (let loop ()
                                    (set! samples (cons (sample! pids t0 n-posed) samples))
                                    (thread-sleep! 1)
                                    (if sampling (loop)))))))
  (for-each thread-join!
            (map (lambda (poser i)
                   (thread-start!
                    (make-thread
                     (lambda ()
                       (pose-all! poser (filter (lambda (t) (= (modulo (car t) n-posers) i))
                                                plan))))))
                 posers (iota n-posers)))
  (let* ((results (append-map (lambda (p)
                                (parameterize ((remote-timeout 1300))
                                  (remote-apply (uid->aspace p) (lab-proc 'bench-results) 1200)))
                              posers))
         (events (bench-told 'events t0))
         (holdings (bench-told 'holdings t0)))
    (set! sampling #f)
    (thread-join! sampler)
    (thread-join! prober)
    (stop-all-processes!)
    (remove-test-lab! lab)
    (list posed-at posed-by events holdings (reverse samples)
          (count (lambda (r) (ok? (cadr r))) results) floor-calls)))

(define (ok? result) (and (list? result) (every symbol? result)))

;; Once a second: (SECOND LAB-CPU-US STARTED QUEUED POSERS-CPU-US), the
;; posers' CPU apart, to see where the lab's goes; told as it goes, so
;; that a run cut short still tells how far it got.
(define (sample! pids t0 n-posed)
  (let* ((started (eval 'started (lab-environment)))
         (s (list (- (current-second) t0) (processes-cpu-us pids) started
                  (- n-posed started) (processes-cpu-us (take pids n-posers)))))
    (write-string (string-append "sched-scale: at " (number->string (round (car s)))
                                 " s: lab cpu " (number->string (round (/ (cadr s) 1e6)))
                                 " s (posers " (number->string (round (/ (list-ref s 4) 1e6)))
                                 " s), started " (number->string started)
                                 ", queued " (number->string (list-ref s 3)) "\n")
                  (current-error-port))
    s))

;; MURDOCH_SCHED_SCALE_SAVE names a file the run is written to, and
;; MURDOCH_SCHED_SCALE_REPLAY one to judge again rather than run the lab
;; (the same sizes and seed), so that a judge's change is tried on a
;; run already made.
(define recorded
  (cond ((get-environment-variable "MURDOCH_SCHED_SCALE_REPLAY")
         => (lambda (file) (call-with-input-file file read)))
        (else
         (let ((r (run-lab!)))
           (cond ((get-environment-variable "MURDOCH_SCHED_SCALE_SAVE")
                  => (lambda (file)
                       (call-with-output-file file (lambda (out) (write r out))))))
           r))))
(define posed-at (list-ref recorded 0))
(define posed-by (list-ref recorded 1))
(define events (list-ref recorded 2))
(define holdings (list-ref recorded 3))
(define samples (list-ref recorded 4))
;; A run saved before the floor was measured has none.
(define floor-calls (if (> (length recorded) 6) (list-ref recorded 6) '()))

;;; The figures

(define tasks (map (lambda (t) (list (car t) (map accepted (cadr t)) (list-ref t 2)
                                     (list-ref t 3) 0))
                   plan))
(define run (make-schedule-run tasks posed-at posed-by events holdings robots aging))
(schedule-completed! run (list-ref recorded 5))
(bench "sched-scale-robots" n-robots "")
(bench "sched-scale-posers" n-posers "")
(print-schedule-figures run "sched-scale")
(when (pair? floor-calls)
  (let ((floor-p95 (* 1000 (percentile floor-calls 0.95))))
    (bench "sched-scale-floor-5-calls-p50" (round-to (* 1000 (percentile floor-calls 0.5)) 1) "ms")
    (bench "sched-scale-floor-5-calls-p95" (round-to floor-p95 1) "ms")
    (bench "sched-scale-last-release-p95-over-floor"
           (round-to (/ (percentile (schedule-last-release-latencies run) 0.95) floor-p95) 2)
           "x")))

;; The CPU per task started over the seconds whose queue, at their start
;; and end, was within a factor sqrt 2 of q, of the lab, or of its posers
;; alone if posers? is true; #f if no second's queue was.
(define (cpu-per-start q posers?)
  (let loop ((ss samples) (cpu 0) (starts 0))
    (if (or (null? ss) (null? (cdr ss)))
        (and (> starts 0) (/ cpu starts))
        (let* ((a (car ss)) (b (cadr ss))
               (cpu-of (lambda (s) (list-ref s (if posers? 4 1))))
               (within? (lambda (s) (<= (/ q (sqrt 2)) (list-ref s 3) (* q (sqrt 2))))))
          (if (and (within? a) (within? b))
              (loop (cdr ss) (+ cpu (- (cpu-of b) (cpu-of a)))
                    (+ starts (- (list-ref b 2) (list-ref a 2))))
              (loop (cdr ss) cpu starts))))))

(define (cpu-line name q posers?)
  (let ((us (cpu-per-start q posers?)))
    (bench name (if us (round us) "none") "us")
    us))

(bench "sched-scale-queue-max" (apply max 0 (map (lambda (s) (list-ref s 3)) samples)) "")
(define at-500 (cpu-line "sched-scale-cpu-per-start-us-at-500" 500 #f))
(define at-2000 (cpu-line "sched-scale-cpu-per-start-us-at-2000" 2000 #f))
(cpu-line "sched-scale-posers-cpu-per-start-us-at-500" 500 #t)
(cpu-line "sched-scale-posers-cpu-per-start-us-at-2000" 2000 #t)
(if (and at-500 at-2000)
    (bench "sched-scale-cpu-per-start-growth" (round-to (/ at-2000 at-500) 3) "x"))
(bench "sched-scale-log-growth" (round-to (/ (log 2000) (log 500)) 3) "x")
