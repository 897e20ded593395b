;;; Tasks that wait their turn, between real address spaces: a task
;;; posed while every capable robot is busy waits, says why and where it
;;; stands, and starts when a robot frees, best rank first and, within a
;;; priority, first posed first, across posers; one no robot could ever
;;; take fails at once; cancel, deadline, the per-poser limit, bad
;;; options, and a robot killed while tasks wait.  Workstations stand in
;;; for robots; a component "holds" its robot until the test opens its
;;; gate there.
;;; tests/run: long
(import (except (scheme base) lambda define) (scheme write) (scheme eval) (scheme time)
        (srfi 1) (srfi 18) (chibi test)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness))

(define lab-code "
;; Each component counts, on its robot, how many run there at once, and
;; notes its label and a ticket from p1, whose numbers give the order the
;; components started in.
(define ticket 0)
(define (next-ticket!) (set! ticket (+ ticket 1)) ticket)
(define inside 0)
(define most-inside 0)
(define starts '())
(define open-gates '())
(define (open-gate! gate) (set! open-gates (cons gate open-gates)))
(define (job label gate)
  (lambda ()
    (set! inside (+ inside 1))
    (set! most-inside (max most-inside inside))
    (set! starts (cons (list label (remote-apply (uid->aspace 'p1) next-ticket!))
                       starts))
    (dynamic-wind
     (lambda () #f)
     (lambda ()
       (let loop ()
         (if (and gate (not (memq gate open-gates)))
             (begin (thread-sleep! 0.05) (loop))))
       (thread-sleep! 0.1)
       label)
     (lambda () (set! inside (- inside 1))))))
;; A component that keeps its robot for seconds.
(define (slow-job label seconds)
  (lambda () ((job label #f)) (thread-sleep! seconds) label))
;; A step's procedure: the same, applied to the step before's results.
(define (step-job label) (lambda (previous) ((job label #f))))
;; What the posers p1 and p2 run: a one-robot task that waits.
(define posed-here '())
(define (pose-job label)
  (set! posed-here
        (cons (start-task 'job 1 (list '((arm) ())) (list #f) (list (job label #f))
                          'wait #t)
              posed-here))
  #t)
")

(define lab
  (make-test-lab
   '((code "code.scm") (heartbeat 0.2) (max-waiting 20) (aging 1)
     (aspace tester)
     (aspace p1)
     (aspace p2)
     (aspace r1 (capabilities arm))
     (aspace r2 (capabilities arm))
     (aspace r3 (capabilities arm lift))
     ;; A lift alone: it leaves the lab, and joins again, while a task waits.
     (aspace r4 (capabilities lift)))
   `(("code.scm" . ,lab-code))))

(define pids
  (map (lambda (uid) (cons uid (start-lab-aspace! lab uid)))
       '(p1 p2 r1 r2 r3 r4)))
(join-lab (test-lab-file lab) 'tester)
(wait-until 10 (lambda () (= 6 (length (filter (lambda (u) (memq u '(p1 p2 r1 r2 r3 r4)))
                                                (live-uids))))))

(define (lab-proc name) (eval name (lab-environment)))
(define (job label gate) ((lab-proc 'job) label gate))
(define (robot-value uid name)
  (remote-apply (uid->aspace uid) (eval `(lambda () ,name) (lab-environment))))
(define (open-gate! uid gate)
  (remote-apply (uid->aspace uid) (lab-proc 'open-gate!) gate))
(define (state-of task k) (status-state (list-ref (task-status task) (- k 1))))
(define (all-free?)
  (every (lambda (r) (every (lambda (s) (null? (cadr s))) (cadr r)))
         (request-status 'arm)))

;; Holds robot uid with a task until gate is opened there.
(define (block! uid gate)
  (let ((t (start-task 'block 1 (list `((arm ,uid) ())) (list #f)
                       (list (job gate gate)))))
    (wait-until 10 (lambda () (eq? (car (state-of t 1)) 'running)))
    t))

;; Whether t waits: the task, or its first component (a lost one, again).
(define (waiting? t)
  (and (or (memq (car (state-of t 1)) '(waiting holding))
           (memq (task-state t) '(waiting holding)))
       #t))

(define (wait-job label . options)
  (apply start-task 'job 1 (list '((arm) ())) (list #f) (list (job label #f))
         'wait #t options))

;; The labels that started on the robots, first started first.
(define (start-order labels)
  (map car
       (sort (filter (lambda (s) (memq (car s) labels))
                     (append-map (lambda (uid)
                                   (guard (e (#t '())) (robot-value uid 'starts)))
                                 '(r1 r2 r3)))
             (lambda (a b) (< (cadr a) (cadr b))))))

(define (sort ls less?)
  (if (null? ls)
      '()
      (let ((pivot (car ls)))
        (append (sort (filter (lambda (x) (less? x pivot)) (cdr ls)) less?)
                (list pivot)
                (sort (remove (lambda (x) (less? x pivot)) (cdr ls)) less?)))))

(define (waiting-count)
  (length (append-map cadr (request 'waiting-tasks waiting-ranks))))

(test-begin "tasks that wait their turn")

(test-group "the thesis's answer stays the default"
  (let ((blocks (map block! '(r1 r2 r3) '(d1 d2 d3))))
    (test "a task that does not wait answers not-enough-takers at once"
        'not-enough-takers
      (task-wait (start-task 'job 1 (list '((arm) ())) (list #f) (list (job 'x #f))) 10))
    (for-each open-gate! '(r1 r2 r3) '(d1 d2 d3))
    (for-each (lambda (t) (task-wait t 10)) blocks)))

(test-group "a task posed while every robot is busy waits, then runs"
  (let* ((blocks (map block! '(r1 r2 r3) '(g1 g2 g3)))
         (w (wait-job 'w)))
    (test "it waits" #t (wait-until 10 (lambda () (waiting? w))))
    (test "first in line" 1 (cadr (state-of w 1)))
    (test-assert "it says which robots are busy, and with which task"
      (let ((why (car (cddr (state-of w 1)))))
        (and (text-contains? why "r1 held by block@")
             (text-contains? why "r3 held by block@"))))
    (test "(tasks) shows it waiting, with its place" (list 'waiting 1)
      (let ((entry (find (lambda (e) (eq? (listed-id e) (task-id w))) (tasks))))
        (list (listed-state entry) (listed-place entry))))
    (test-assert "the lab's status shows it, with its place and why"
      (let ((out (open-output-string)))
        (show-status out)
        (let ((text (get-output-string out)))
          (and (text-contains? text (string-append (symbol->string (task-id w))
                                                   " waiting: waits for 1 (arm); 1st in line"))
               (text-contains? text "r1 held by block@")))))
    (test-assert "it holds nothing: every arm is held by a blocker"
      (every (lambda (r) (every (lambda (s) (or (null? (cadr s))
                                                 (text-contains? (symbol->string (cadr s))
                                                                 "block@")))
                                (cadr r)))
             (request-status 'arm)))
    (open-gate! 'r2 'g2)
    (test "it runs on the robot that freed" '(w) (task-wait w 10))
    (test "on r2" 'r2 (car (car (status-attempts (list-ref (task-status w) 0)))))
    (for-each open-gate! '(r1 r3) '(g1 g3))
    (for-each (lambda (t) (task-wait t 10)) blocks)
    (test "every subject is free" #t (wait-until 5 all-free?))))

(test-group "a task no robot of the lab can take fails at once"
  (let ((t (start-task 'fly 1 (list '((wings) ())) (list #f) (list (job 'f #f))
                       'wait #t)))
    (test "not-enough-takers" 'not-enough-takers (task-wait t 10))
    (test-assert "and says so"
      (text-contains? (cadr (state-of t 1)) "no live robot of the lab is capable"))))

(test-group "best rank first, then first posed"
  (let* ((blocks (map block! '(r1 r2 r3) '(h1 h2 h3)))
         (a (wait-job 'a))
         (b (wait-job 'b 'priority 5))
         (c (wait-job 'c)))
    (test "all three wait" #t (wait-until 10 (lambda () (every waiting? (list a b c)))))
    (test "their places: b, then a, then c" '(2 1 3)
      (begin (task-status a)
             (map (lambda (t) (cadr (state-of t 1))) (list a b c))))
    (open-gate! 'r1 'h1)
    (for-each (lambda (t) (task-wait t 20)) (list a b c))
    (test "they started in rank order" '(b a c) (start-order '(a b c)))
    (for-each open-gate! '(r2 r3) '(h2 h3))
    (for-each (lambda (t) (task-wait t 10)) blocks)))

(test-group "first posed, first served, across three posers"
  (let ((blocks (map block! '(r1 r2 r3) '(k1 k2 k3)))
        (mine '()))
    (define (pose! where label)
      (if (eq? where 'tester)
          (set! mine (cons (wait-job label) mine))
          (remote-apply (uid->aspace where) (lab-proc 'pose-job) label))
      (wait-until 10 (lambda () (>= (waiting-count)
                                    (length (memq label '(f5 f4 f3 f2 f1)))))))
    (for-each pose! '(p1 tester p2 p1 tester) '(f1 f2 f3 f4 f5))
    (test "five wait, lab-wide" 5 (waiting-count))
    (test "this poser's places count the other posers' tasks: 2nd and 5th" '(2 5)
      (let ((places (lambda ()
                      (map (lambda (t)
                             (listed-place (find (lambda (e) (eq? (listed-id e) (task-id t)))
                                                 (tasks))))
                           (reverse mine)))))
        (wait-until 10 (lambda () (equal? (places) '(2 5))))
        (places)))
    (open-gate! 'r3 'k3)
    (test "all ran" #t
      (wait-until 20 (lambda () (= 5 (length (start-order '(f1 f2 f3 f4 f5)))))))
    (test "in the order they were posed" '(f1 f2 f3 f4 f5)
      (start-order '(f1 f2 f3 f4 f5)))
    (for-each open-gate! '(r1 r2) '(k1 k2))
    (for-each (lambda (t) (task-wait t 10)) (append mine blocks))))

(test-group "cancel and deadline while waiting"
  (let* ((blocks (map block! '(r1 r2 r3) '(m1 m2 m3)))
         (cancelled (wait-job 'cancelled))
         (late (wait-job 'late 'deadline 0.5)))
    (test "both wait" #t (wait-until 10 (lambda () (waiting? cancelled))))
    (cancel-task cancelled)
    (test "a cancelled one ends, cancelled" '(cancelled)
      (begin (task-wait cancelled 5) (state-of cancelled 1)))
    (test "one past its deadline fails with deadline" 'deadline (task-wait late 5))
    (test "deadline, in its state" '(deadline) (state-of late 1))
    (test "the task's word, in (tasks) too" '(cancelled deadline)
      (map (lambda (t)
             (listed-state (find (lambda (e) (eq? (listed-id e) (task-id t))) (tasks))))
           (list cancelled late)))
    (for-each open-gate! '(r1 r2 r3) '(m1 m2 m3))
    (for-each (lambda (t) (task-wait t 10)) blocks)
    (test "neither ever started" '() (start-order '(cancelled late)))
    (test "no task waits" 0 (waiting-count))))

(test-group "at most max-waiting tasks wait per poser"
  (let* ((blocks (map block! '(r1 r2 r3) '(n1 n2 n3)))
         (ws (map (lambda (i) (wait-job 'limited)) (iota 20)))
         (before (length (tasks))))
    (test-assert "one more is refused, saying why"
      (text-contains? (error-text (lambda () (wait-job 'limited))) "max-waiting"))
    (test "and nothing is added" before (length (tasks)))
    (for-each cancel-task ws)
    (for-each (lambda (t) (task-wait t 5)) ws)
    (for-each open-gate! '(r1 r2 r3) '(n1 n2 n3))
    (for-each (lambda (t) (task-wait t 10)) blocks)))

(test-group "bad options get one clear error"
  (for-each
   (lambda (options word)
     (test-assert word
       (text-contains? (error-text (lambda () (apply wait-job 'bad options))) word)))
   '((priority -1) (priority high) (deadline -2) (wait maybe) (soon 3) (priority))
   '("priority" "priority" "deadline" "wait" "no such option" "keywords")))

(define (list-head ls n)
  (if (or (zero? n) (null? ls)) '() (cons (car ls) (list-head (cdr ls) (- n 1)))))

(test-group "no starvation: aging bounds a low-priority task's wait"
  ;; Aging is 1 a second here: a task of priority 1 posed more than 1 s
  ;; after one of priority 0 ranks after it.  r1 alone serves a stream of
  ;; such tasks, posed faster than it runs them.
  (let* ((blocks (map block! '(r2 r3) '(s2 s3)))
         (x1 (block! 'r1 's1))
         (low (wait-job 'patient))
         (low-posed (current-second))
         (highs (map (lambda (i)
                       (thread-sleep! 0.15)
                       (let ((posed (current-second)))
                         (open-gate! 'r1 's1)
                         (cons posed
                               (start-task 'high 1 (list '((arm) ())) (list #f)
                                           (list ((lab-proc 'slow-job)
                                                  (string->symbol
                                                   (string-append "high"
                                                                  (number->string i)))
                                                  0.3))
                                           'wait #t 'priority 1))))
                     (iota 16)))
         (later (filter-map (lambda (h) (and (> (car h) (+ low-posed 1))
                                             (car (task-wait (cdr h) 30))))
                            highs)))
    (task-wait low 30)
    (test-assert "some high-priority tasks were posed past the bound" (pair? later))
    (test "the low-priority task starts before every one of them" '(patient)
      (let ((order (start-order (cons 'patient later))))
        (list-head order 1)))
    (for-each (lambda (h) (task-wait (cdr h) 30)) highs)
    (open-gate! 'r2 's2)
    (open-gate! 'r3 's3)
    (for-each (lambda (t) (task-wait t 10)) (cons x1 blocks))))

(define (holder-of uid)
  (cadr (find (lambda (s) (eq? (car s) 'arm)) (cadr (assq uid (request-status 'arm))))))

;; Whether robot uid is held by a reservation of a task named name.
(define (held-for? uid name)
  (let ((holder (holder-of uid)))
    (and (symbol? holder)
         (text-contains? (symbol->string holder) (string-append name "@")))))

(define (pair-job label)
  (lambda options
    (apply start-task 'pair 2 (list '((arm) ()) '((arm) ())) (list #f #f)
           (list (job label #f) (job label #f)) 'wait #t 'hold #t options)))

(test-group "the classic deadlock: two tasks of two robots, each holding one"
  ;; r3 stays busy, so that two robots serve the two tasks.  low holds r2
  ;; while r1 is busy; high, better-ranked, then wins r1 as it frees, and
  ;; needs r2: each holds one robot and waits for the other.
  (let* ((x3 (block! 'r3 'x3))
         (x1 (block! 'r1 'x1))
         (low ((pair-job 'low) 'priority 0)))
    (test "the lower-ranked one waits, holding the free robot" #t
      (wait-until 10 (lambda () (and (waiting? low) (held-for? 'r2 "pair")))))
    (let ((high ((pair-job 'high) 'priority 5)))
      (test "the better-ranked one waits" #t (wait-until 10 (lambda () (waiting? high))))
      (open-gate! 'r1 'x1)
      (test "both complete" '((high high) (low low))
        (list (task-wait high 20) (task-wait low 20)))
      (test "in rank order" '(high high low low) (start-order '(high low)))
      (open-gate! 'r3 'x3)
      (for-each (lambda (t) (task-wait t 10)) (list x1 x3)))))

(test-group "a task of steps takes start-task's keywords"
  ;; other, posed first at priority 0, waits for any robot; the task of
  ;; steps, posed after it at priority 5, holds r1 as it frees and waits
  ;; for a second robot: without priority it would rank after other, and
  ;; without hold it would not keep r1.
  (let* ((blocks (map block! '(r1 r2 r3) '(v1 v2 v3)))
         (other (wait-job 'other))
         (step-job (lab-proc 'step-job))
         (one-arm (lambda (label)
                    (task-step (list '((arm) ())) (list #f) (list (step-job label)))))
         (stepped (start-steps 'stepped
                               (task-step (list '((arm) ()) '((arm) ())) (list #f #f)
                                          (list (step-job 'step1) (step-job 'step1)))
                               (one-arm 'step2)
                               'wait #t 'hold #t 'priority 5))
         (first-state (lambda ()
                        (let ((steps (task-status stepped)))
                          (if (null? steps)
                              '(not-started)
                              (status-state
                               (car (step-status-entries (car steps)))))))))
    (test "its first step waits" 'waiting
      (begin (wait-until 10 (lambda () (eq? (car (first-state)) 'waiting)))
             (car (first-state))))
    (test "first in line, ahead of a task posed before it" '(1 2)
      (begin (wait-until 10 (lambda () (waiting? other)))
             (task-status stepped)
             (list (cadr (first-state)) (cadr (state-of other 1)))))
    (open-gate! 'r1 'v1)
    (test "it holds the robot that freed, and waits for another" #t
      (wait-until 10 (lambda () (held-for? 'r1 "stepped"))))
    (test "the other task still waits" #t (waiting? other))
    (open-gate! 'r2 'v2)
    (test "both steps run" '((step1 step1) (step2)) (task-wait stepped 20))
    (test "the other task runs after the first step started" 'other
      (begin (task-wait other 20) (last (start-order '(step1 other)))))
    (open-gate! 'r3 'v3)
    (for-each (lambda (t) (task-wait t 10)) blocks)
    (let* ((blocks (map block! '(r1 r2 r3) '(u1 u2 u3)))
           (late (start-steps 'late (one-arm 'late) 'wait #t 'deadline 0.5)))
      (test "one past its deadline fails with deadline" '(deadline) (task-wait late 10))
      (test "and never started" '() (start-order '(late)))
      (for-each open-gate! '(r1 r2 r3) '(u1 u2 u3))
      (for-each (lambda (t) (task-wait t 10)) blocks))
    (test-assert "a bad keyword gets one clear error"
      (text-contains? (error-text (lambda ()
                                    (start-steps 'bad (one-arm 'bad) 'priority -1)))
                      "priority"))))

(test-group "no inversion where robots are of several kinds, in a burst"
  ;; r1 and r2 have an arm; r3 an arm and a lift.  A component that asks
  ;; for an arm accepts either kind; one that asks for a lift, r3 alone.
  (let* ((blocks (map block! '(r1 r2 r3) '(burst1 burst2 burst3)))
         (kind-job (lambda (label caps priority)
                     (start-task 'job 1 (list caps) (list #f) (list (job label #f))
                                 'wait #t 'priority priority)))
         (a (kind-job 'ka '((arm lift) ()) 0))
         (b (kind-job 'kb '((arm) ()) 0))
         (c (kind-job 'kc '((arm) ()) 5))
         (d (kind-job 'kd '((arm lift) ()) 5)))
    (test "all four wait" #t (wait-until 30 (lambda () (every waiting? (list a b c d)))))
    (test "in the lab's one line, in rank order: c, d, a, b" #t
      (let ((places (map (lambda (t)
                           (listed-place (find (lambda (e) (eq? (listed-id e) (task-id t)))
                                               (tasks))))
                         (list c d a b))))
        (and (every integer? places) (apply < places))))
    (open-gate! 'r1 'burst1)
    (task-wait c 10)
    (task-wait b 10)
    (open-gate! 'r3 'burst3)
    (task-wait d 10)
    (task-wait a 10)
    (test (string-append "each freed robot goes to the best-ranked task that can use it:"
                         " r1 to c, then b; r3 to d, then a")
        '(kc kb kd ka)
      (start-order '(ka kb kc kd)))
    (open-gate! 'r2 'burst2)
    (for-each (lambda (t) (task-wait t 10)) blocks)))

(test-group "a holding task that holds the one robot another of its components needs gives it up"
  ;; pair's first component, a lift, is negotiated first and takes r3
  ;; while r4 is busy; its second needs an arm and a lift, r3 alone.
  ;; Held for the first, r3 is what the second waits for: no robot that
  ;; frees could serve it, and the task waited on itself for ever.
  (let* ((block (start-task 'block 1 (list '((lift r4) ())) (list #f)
                            (list (job 'self4 'self4))))
         (running (wait-until 10 (lambda () (eq? (car (state-of block 1)) 'running))))
         (pair (start-task 'pair 2 (list '((lift) ()) '((arm lift) ())) (list #f #f)
                           (list (job 'self-lift #f) (job 'self-both #f))
                           'wait #t 'hold #t)))
    (test "it holds r3 for its second component, and waits for r4" '(holding r3)
      (and (wait-until 20 (lambda () (equal? (state-of pair 2) '(holding r3))))
           (state-of pair 2)))
    (open-gate! 'r4 'self4)
    (test "both run once r4 frees" '(self-lift self-both) (task-wait pair 20))
    (test "the lift on r4, the arm and lift on r3" '(r4 r3)
      (map (lambda (s) (car (car (status-attempts s)))) (task-status pair)))
    (task-wait block 10)))

(test-group "a robot that joins the lab again offers itself to the tasks that wait for it"
  (kill-process! (cdr (assq 'r4 pids)))
  (wait-until 20 (lambda () (not (memq 'r4 (live-uids)))))
  ;; r3's lift is held, as its arm: a task that holds only its arm
  ;; leaves its lift free for others.
  (let* ((block (let ((t (start-task 'block 1 (list '((arm lift r3) ())) (list #f)
                                     (list (job 'joins3 'joins3)))))
                  (wait-until 10 (lambda () (eq? (car (state-of t 1)) 'running)))
                  t))
         (lifter (start-task 'lift 1 (list '((lift) ())) (list #f) (list (job 'joined #f))
                             'wait #t)))
    (test "a lift task waits while r3, the one lift left, is busy" #t
      (wait-until 10 (lambda () (waiting? lifter))))
    (set! pids (cons (cons 'r4 (start-lab-aspace! lab 'r4)) pids))
    (test "r4 joins, and takes it" '(joined) (task-wait lifter 20))
    (test "on r4" 'r4 (car (car (status-attempts (list-ref (task-status lifter) 0)))))
    (open-gate! 'r3 'joins3)
    (task-wait block 10)))

(test-group "a robot killed while tasks wait"
  ;; mover, restartable, runs on r3 while r1 and r2 are busy; lifter can
  ;; only have r3, armer any robot.
  (let* ((blocks (map block! '(r1 r2) '(q1 q2)))
         (mover (start-task 'mover 1 (list '((arm) ())) (list #f) (list (job 'mover 'q3))
                            '(1) '(#t) 'wait #t))
         (running (wait-until 10 (lambda () (eq? (car (state-of mover 1)) 'running))))
         (lifter (start-task 'lift 1 (list '((arm lift) ())) (list #f)
                             (list (job 'lift #f)) 'wait #t))
         (armer (wait-job 'armer)))
    (for-each (lambda (uid) (open-gate! uid 'q3)) '(r1 r2))
    (test "both wait" #t
      (wait-until 10 (lambda () (and (waiting? lifter) (waiting? armer)))))
    (kill-process! (cdr (assq 'r3 pids)))
    (test "the one only r3 could take fails, saying so" 'not-enough-takers
      (task-wait lifter 10))
    (test "a restartable component that was lost waits for another robot" #t
      (wait-until 10 (lambda () (waiting? mover))))
    (test "the other waits on for the others" #t (waiting? armer))
    (open-gate! 'r1 'q1)
    (test "the lost component runs when a robot frees" '(mover) (task-wait mover 10))
    (test "its attempts: lost on r3, done on r1" '((r3 lost) (r1 done))
      (map (lambda (a) (list (car a) (cadr a)))
           (status-attempts (car (task-status mover)))))
    (test "and the other after it: it ranks first, posed first" '(armer)
      (task-wait armer 10))
    (test "in that order (r3's notes died with it)" '(mover armer)
      (start-order '(mover armer)))
    (open-gate! 'r2 'q2)
    (for-each (lambda (t) (task-wait t 10)) blocks)))

(test-group "at the end"
  (test "no robot ever ran two exclusive components at once, seen from inside"
      '(1 1)
    (map (lambda (uid) (robot-value uid 'most-inside)) '(r1 r2)))
  (test-assert "nothing is held" (every null? (map holder-of '(r1 r2))))
  (test "no reservation is held" #t (wait-until 5 all-free?))
  (test "no task waits" 0 (waiting-count)))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
