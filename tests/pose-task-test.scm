;;; pose-task between real address spaces: choice by metric, conflicts,
;;; failure that frees everything, a one-robot task, errors, and two tasks
;;; posed at once.  Workstations stand in for robots here (their positions
;;; come from the lab file); tests/transcripts drive the simulated robots.
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (srfi 1) (srfi 18) (srfi 132) (chibi test)
        (only (chibi ast) thread-interrupt!)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness)
        (only (murdoch pubsub messaging) request-components))

(define lab-code "
;; A component that says who ran it, holding its robot a moment.
(define (who-am-i) (thread-sleep! 0.2) (local-aspace-uid))
(define (fail) (error \"the component broke\"))
(define (linger) (thread-sleep! 2) 'lingered)
;; A component that never ends by itself, calling out all the time.
(define spins 0)
(define started #f)
(define (start-spinning) (set! started #t) (spin))
(define (spin)
  (set! spins (+ spins 1))
  (remote-apply (uid->aspace 'quiet) (lambda () #t))
  (thread-sleep! 0.05)
  (spin))
(define (free-everywhere? subjects)
  (every (lambda (r) (every (lambda (s) (null? (cadr s))) (cadr r)))
         (request 'all (lambda ()
                         (filter-map (lambda (t)
                                       (let ((s (topic-status t))) (and s (list t s))))
                                     subjects)))))
(define (pose-one name)
  (pose-task name 1 (list '((mobile) ())) (list #f) (list who-am-i)))
")

(define lab
  (make-test-lab
   '((code "code.scm") (lease 30)
     (aspace tester)
     (aspace near (position 100 100 0) (capabilities mobile sonar) (load 0.5))
     (aspace far (position 3000 3000 0) (capabilities mobile sonar) (load 0.5))
     (aspace busy (position 0 0 0) (load 0.6))
     (aspace quiet (position 0 0 0) (load 0.1)))
   `(("code.scm" . ,lab-code))))


(for-each (lambda (uid) (start-lab-aspace! lab uid)) '(near far busy quiet))
(join-lab (test-lab-file lab) 'tester)

(define (lab-proc name) (eval name (lab-environment)))
(define who-am-i #f)
(define fail #f)
(define linger #f)
(define spin #f)
(define start-spinning #f)
(set! who-am-i (lab-proc 'who-am-i))
(set! start-spinning (lab-proc 'start-spinning))
(set! spin (lab-proc 'spin))
(set! fail (lab-proc 'fail))
(set! linger (lab-proc 'linger))
(define (all-free?) ((lab-proc 'free-everywhere?) '(mobile sonar idle)))

(test-begin "pose-task")

(test "resolve-conflicts: the first list wins, later ones take the next"
    '((a 1) (b 2) (c 3))
  (resolve-conflicts '(((a 1) (b 1)) ((a 2) (b 2)) ((c 3) (a 3)))))
(test "resolve-conflicts: #f when a list runs out" #f
  (resolve-conflicts '(((a 1)) ((a 2)))))
(test "resolve-conflicts: the higher priority picks first, picks in list order"
    '((b 1) (a 2) (c 3))
  (resolve-conflicts '(((a 1) (b 1)) ((a 2) (b 2)) ((c 3) (a 3))) '(1 2 0)))

(test "the closest robot gets each target, the least loaded the sums"
    '(near far quiet)
  (pose-task 'two-targets 3
             (list '((mobile) (sonar)) '((mobile) (sonar)) 'idle)
             (list (location-metric-maker '(0 0 0 0))
                   (location-metric-maker '(0 0 0 0))
                   load-metric)
             (list who-am-i who-am-i who-am-i)))
(test "and afterwards every subject is free" #t (all-free?))

(test "a metric that prefers the farther robot" '(far)
  (pose-task 'far-away 1 (list '((mobile) ()))
             (list (reverse-metric (location-metric-maker '(0 0 0 0))))
             (list who-am-i)))

;; Greedy gives the first component near, a little closer to it, and the
;; second is left far, very far from its target: 1980 + 4243 mm.  The
;; least total swaps them: 2121 + 141 mm.
(define (two-targets-task)
  (list 'swap 2 (list '((mobile) ()) '((mobile) ()))
        (list (location-metric-maker '(1500 1500 0 0))
              (location-metric-maker '(0 0 0 0)))
        (list who-am-i who-am-i)))
(test "greedy, the default: the first component takes its closest" '(near far)
  (apply pose-task (two-targets-task)))
(test "optimal: the least total distance" '(far near)
  (parameterize ((pose-task-assignment 'optimal))
    (apply pose-task (two-targets-task))))
(test "explicit priorities: the second component chooses first" '(far near)
  (apply pose-task (append (two-targets-task) (list '(1 2)))))
(test "equal priorities keep the components' order" '(near far)
  (apply pose-task (append (two-targets-task) (list '(3 3)))))
(test "optimal takes more candidates than components" '(far)
  (parameterize ((pose-task-assignment 'optimal))
    (pose-task 'one-of-two 1 (list '((mobile) ()))
               (list (location-metric-maker '(3000 3000 0 0))) (list who-am-i))))

;; The progress output of thunk, a pose-task.
(define (progress-of thunk)
  (let ((out (open-output-string)))
    (parameterize ((pose-task-progress out)) (thunk))
    (get-output-string out)))
(test "under optimal, a component without one measure keeps the greedy rule, and says so"
    '(#t #t)
  (let ((text (progress-of
               (lambda ()
                 (parameterize ((pose-task-assignment 'optimal))
                   (pose-task 'mixed 2 (list '((mobile) ()) '((mobile) ()))
                              (list #f (location-metric-maker '(0 0 0 0)))
                              (list who-am-i who-am-i)))))))
    (list (text-contains? text "component 1 is not by one measure: greedy")
          (text-contains? text "optimal assignment: total"))))
(test "and every subject is free" #t (all-free?))

;; near measures 100 and far 105 by the first metric, 2 and 1 by the
;; second; each measure counts the candidates it is asked about.
(define asked '())
(define (counted key value)
  (metric-by (lambda (uid)
               (set! asked (cons key asked))
               (value uid))))
(define (by-first) (counted 'first (lambda (uid) (if (eq? uid 'near) 100 105))))
(define (by-second) (counted 'second (lambda (uid) (if (eq? uid 'near) 2 1))))
(define (pose-by metric)
  (set! asked '())
  (pose-task 'composed 1 (list '((mobile) ())) (list metric) (list who-am-i)))
(test "composed: the first metric decides when it does not tie" '(near)
  (pose-by (compose-metrics (by-first) (by-second))))
(test "composed: within its tolerance the first ties, and the second decides"
    '(far)
  (pose-by (compose-metrics (metric-within 10 (by-first)) (by-second))))
(test "each candidate was measured once by each measure" '(2 2)
  (list (count (lambda (k) (eq? k 'first)) asked)
        (count (lambda (k) (eq? k 'second)) asked)))
(test "the tolerance is a tie, not a preference: out of it, the first decides"
    '(near)
  (pose-by (compose-metrics (metric-within 4 (by-first)) (by-second))))
(test "reversed, a composed metric reverses each of its metrics" '(near)
  (pose-by (reverse-metric (compose-metrics (metric-within 10 (by-first))
                                            (by-second)))))
(test "composed with a comparator, which ties when it prefers neither" '(far)
  (pose-by (compose-metrics (lambda (a b) #f) (by-second))))
(test "a tolerance takes a metric by one measure"
    "metric-within: a tolerance >= 0 and a metric by one measure"
  (error-text (lambda () (metric-within 1 (lambda (a b) #t)))))

(test "a candidate that cannot be measured comes last" '(far)
  (pose-task 'unmeasured 1 (list '((mobile) ()))
             (list (metric-by (lambda (uid)
                                (if (eq? uid 'near) (error "no answer") 1))))
             (list who-am-i)))

(test "a candidate whose answer fails there comes last, when asked" '(far)
  (pose-task 'unanswered 1 (list '((mobile) ()))
             (list (metric-by-asking
                    (lambda () (if (eq? (local-aspace-uid) 'near) (error "no") 1))
                    (lambda (answer) answer)))
             (list who-am-i)))

(test "a candidate whose answer does not score comes last, when asked" '(far)
  (pose-task 'unscored 1 (list '((mobile) ()))
             (list (metric-by-asking local-aspace-uid
                                     (lambda (uid) (if (eq? uid 'near) 'none 1))))
             (list who-am-i)))

(test "a candidate whose score raises comes last, and the others are scored" '(far)
  (pose-task 'score-raises 1 (list '((mobile) ()))
             (list (metric-by-asking local-aspace-uid
                                     (lambda (uid) (if (eq? uid 'near) (car '()) 1))))
             (list who-am-i)))
(test "and when every score raises, the task is still placed" #t
  (and (memq (car (pose-task 'scores-raise 1 (list '((mobile) ()))
                             (list (metric-by-asking local-aspace-uid
                                                     (lambda (uid) (car '()))))
                             (list who-am-i)))
             '(near far))
       #t))

;; pose-task's round: one message to each address space for all the
;; components, each candidate's promise with its answers to the askings.
(define (round-of components)
  (let ((round (request-components 'round@tester components)))
    (for-each (lambda (component)
                (for-each (lambda (entry)
                            (if (procedure? (cadr entry)) ((cadr entry) #f)))
                          (car component)))
              round)
    (map (lambda (component)
           (list (list-sort symbol<? (map car (car component)))
                 (list-sort (lambda (a b) (symbol<? (car a) (car b)))
                            (cadr component))))
         round)))
(define (symbol<? a b) (string<? (symbol->string a) (symbol->string b)))
(test "request-components: each component's candidates, and their answers to the askings"
    '(((far near) ((far (#t far) (#f "no")) (near (#t near) (#f "no"))))
      ((near) ((near))))
  (round-of (list (list 'exclusive '((mobile) ()) who-am-i
                        (list local-aspace-uid (lambda () (error "no"))))
                  (list 'non-exclusive '(() (near)) t '()))))
(test "and the round's promises, applied to #f, free what they reserved" #t
  (all-free?))

(test "a one-robot task frees its robot" #t
  (begin (pose-task 'one 1 (list '((mobile) ())) (list #f) (list who-am-i))
         (all-free?)))

(test "three mobile components, two mobile robots: not enough takers"
    'not-enough-takers
  (pose-task 'too-big 3 (list '((mobile) ()) '((mobile) ()) '((mobile) ()))
             (list #f #f #f) (list who-am-i who-am-i who-am-i)))
(test "and every reservation is freed" #t (all-free?))

(test "a capability nobody has: not enough takers" 'not-enough-takers
  (pose-task 'no-arm 2 (list '((mobile) ()) '((arm) ()))
             (list #f #f) (list who-am-i who-am-i)))
(test "and the robot promised for the first component is free" #t (all-free?))

(test "an error in one component is reported, the others finish"
    '(near (error far "the component broke"))
  (pose-task 'half-broken 2 (list '((mobile) ()) '((mobile) ()))
             (list (location-metric-maker '(0 0 0 0))
                   (location-metric-maker '(0 0 0 0)))
             (list who-am-i fail)))
(test "and nothing stays reserved" #t (all-free?))

;; Its caller gives up; the component runs on, holding its robot.
(test "a component that outlives (task-timeout) is told as failed"
    '((error near "no answer within 1 s"))
  (parameterize ((task-timeout 1))
    (pose-task 'slow 1 (list '((mobile) ()))
               (list (location-metric-maker '(0 0 0 0))) (list linger))))
(test "and its robot is freed when it ends" #t (wait-until 10 all-free?))

;; One that would never end is stopped where it next calls out.  Its
;; robot is asked directly: a request leaves out one that counts as away,
;; as one whose caller gave up does for a moment.
(define endless
  (parameterize ((task-timeout 1))
    (pose-task 'endless 1 (list '((mobile) ()))
               (list (location-metric-maker '(0 0 0 0))) (list spin))))
(define (on-spinner proc) (remote-apply (uid->aspace (cadr (car endless))) proc))
;; Whether what (read) counts stays the same for 0.3 s.
(define (settles? read)
  (let ((before (read)))
    (thread-sleep! 0.3)
    (= before (read))))
(test "a component that never ends is told as failed too"
    '(error "no answer within 1 s")
  (list (car (car endless)) (car (cddr (car endless)))))
(test "then stops at its next remote call, freeing its robot" #t
  (wait-until 10 (lambda () (null? (on-spinner (lambda () (topic-status 'mobile)))))))
(test "and calls out no more" #t
  (settles? (lambda () (on-spinner (lambda () spins)))))

;; A component that the posing address space wins itself runs here, and
;; (task-timeout) bounds it all the same.
(test "a component run where it was posed is told as failed on time"
    '((error tester "no answer within 1 s"))
  (parameterize ((task-timeout 1))
    (pose-task 'at-home 1 (list '(() (tester))) (list #f) (list spin))))
(test "and stops at its next remote call" #t
  (wait-until 10 (lambda () (settles? (lambda () (lab-proc 'spins))))))

;; Ctrl-C at the REPL interrupts the thread that poses: its components
;; are given up at once, not after (task-timeout).
(define (on-robot uid proc) (remote-apply (uid->aspace uid) proc))
(define (robots-where what) (filter (lambda (uid) (on-robot uid what)) '(near far)))
(define (holding-mobile) (robots-where (lambda () (not (null? (topic-status 'mobile))))))
(test "an interrupted pose-task raises the interrupt" 'interrupted
  (let ((poser (make-thread
                (lambda ()
                  (guard (e (#t 'interrupted))
                    (pose-task 'interrupted 1 (list '((mobile) ())) (list #f)
                               (list start-spinning)))))))
    (thread-start! poser)
    (wait-until 10 (lambda () (pair? (robots-where (lambda () started)))))
    (thread-interrupt! poser)
    (thread-join! poser)))
(test "and its component stops, freeing the robot" '()
  (begin
    (wait-until 10 (lambda () (null? (holding-mobile))))
    (holding-mobile)))

(test "a metric that is neither a procedure nor #f is a clear error"
    "pose-task: a metric is a procedure or #f"
  (error-text (lambda ()
                (pose-task 'bad 1 (list 'idle) (list 'nearest) (list who-am-i)))))
(test "so is a component that is not a procedure"
    "pose-task: a component's procedure is not a procedure"
  (error-text (lambda () (pose-task 'bad 1 (list 'idle) (list #f) (list 42)))))
(test "and a bad subject in a later component, before anything is reserved"
    '("pose-task: a subject is a symbol" #t)
  (list (error-text (lambda ()
                   (pose-task 'bad 2 (list '((mobile) ()) '(("sonar") ()))
                              (list #f #f) (list who-am-i who-am-i))))
        (all-free?)))

(test "a wrong number of components is a clear error"
    "pose-task: num-robots, capabilities, metrics and procedures do not agree"
  (error-text (lambda () (pose-task 'wrong 2 (list 'idle) (list #f) (list who-am-i)))))

;; Two address spaces pose a one-robot task each, at once, ten times:
;; they never get the same robot at once, and never deadlock.
(let* ((here (make-thread
              (lambda ()
                (map (lambda (i) ((lab-proc 'pose-one) 'from-tester)) (iota 10)))))
       (there (make-thread
               (lambda ()
                 (let ((pose-one (lab-proc 'pose-one)))
                   (parameterize ((remote-timeout 120))
                     (remote-apply (uid->aspace 'busy)
                                   (lambda ()
                                     (map (lambda (i) (pose-one 'from-busy))
                                          (iota 10))))))))))
  (thread-start! here) (thread-start! there)
  (let ((mine (thread-join! here))
        (theirs (thread-join! there)))
    (test "two tasks posed at once: each pose ends, with a robot or not"
        20
      (length (filter (lambda (r) (or (eq? r 'not-enough-takers) (pair? r)))
                      (append mine theirs))))
    (test "the robots they got were mobile ones" #t
      (every (lambda (r) (or (eq? r 'not-enough-takers)
                             (and (memq (car r) '(near far)) #t)))
             (append mine theirs)))
    (test "and afterwards every subject is free" #t (all-free?))))

;; A metric as the thesis writes one: a comparison that asks both
;; candidates where they are, so that each call of the sort's comparator,
;; which Chibi runs from C, waits on the network.  Three threads here pose
;; with it at once, five times each: every pose ends.
(define (closer-to-origin e1 e2)
  (let ((distance (lambda (entry)
                    (reckon-distance-between
                     '(0 0 0 0)
                     (remote-apply (uid->aspace (car entry)) safe-reckon)))))
    (< (distance e1) (distance e2))))

(let* ((poser (lambda (name)
                (make-thread
                 (lambda ()
                   (map (lambda (i)
                          (pose-task name 1 (list '((mobile) ()))
                                     (list closer-to-origin) (list who-am-i)))
                        (iota 5))))))
       (threads (map poser '(asker-1 asker-2 asker-3))))
  (for-each thread-start! threads)
  (let ((results (append-map (lambda (t) (thread-join! t 120 '(lost))) threads)))
    (test "poses whose comparator asks the robots, three at once, all end" 15
      (length (filter (lambda (r) (or (eq? r 'not-enough-takers)
                                      (equal? r '(near)) (equal? r '(far))))
                      results)))
    (test "and afterwards every subject is free" #t (all-free?))))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
