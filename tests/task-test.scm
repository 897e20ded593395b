;;; The task life cycle between real address spaces: start-task and its
;;; record, task-wait, cancel-task, a lost robot's component given to
;;; another, no orphans when the poser dies, and no ghosts when a frozen
;;; robot comes back.  Workstations stand in for robots, as in
;;; pose-task-test; a component "calls out" to quiet, where it would send
;;; robot commands, and stops where it next does so.
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (srfi 1) (srfi 18) (chibi test)
        (only (chibi process) kill signal/stop signal/continue)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (only (murdoch lab) current-lab) (murdoch cli command) (murdoch testing harness))

(define lab-code "
;; Each component's setup and cleanup count, here, how often they run.
(define ins 0)
(define outs 0)
(define (counted thunk)
  (dynamic-wind (lambda () (set! ins (+ ins 1)))
                thunk
                (lambda () (set! outs (+ outs 1)))))
(define (who-am-i) (counted (lambda () (thread-sleep! 0.2) (local-aspace-uid))))
(define (fail) (counted (lambda () (error \"the component broke\"))))
;; A component that runs until stopped, calling out all the time; spins
;; counts its rounds here, stopped says how it ended.
(define spins 0)
(define stopped #f)
(define (spin-for rounds)
  (dynamic-wind
   (lambda () (set! ins (+ ins 1)))
   (lambda ()
     (let loop ((n rounds))
       (set! spins (+ spins 1))
       (remote-apply (uid->aspace 'quiet) (lambda () #t))
       (thread-sleep! 0.05)
       (if (> n 0) (loop (- n 1)) (local-aspace-uid))))
   (lambda () (set! stopped #t) (set! outs (+ outs 1)))))
;; A component that counts how many components run here at once.
(define inside 0)
(define most-inside 0)
(define (crowd)
  (set! inside (+ inside 1))
  (set! most-inside (max most-inside inside))
  (dynamic-wind (lambda () #f)
                (lambda () (spin-for 6))
                (lambda () (set! inside (- inside 1)))))
(define (spin) (spin-for 50))
(define (spin-long) (spin-for 1000))
(define (free-everywhere? subjects)
  (every (lambda (r) (every (lambda (s) (null? (cadr s))) (cadr r)))
         (request 'all (lambda ()
                         (filter-map (lambda (t)
                                       (let ((s (topic-status t))) (and s (list t s))))
                                     subjects)))))
;; Run by the poser address space: starts a task that spins long on one
;; mobile robot.
(define (start-spinning)
  (start-task 'orphan 1 (list '((mobile) ()))
              (list (location-metric-maker '(0 0 0 0))) (list spin-long))
  #t)
")

(define lab
  (make-test-lab
   '((code "code.scm") (lease 30) (heartbeat 0.3) (max-attempts 3)
     (aspace tester)
     (aspace poser)
     (aspace near (position 100 100 0) (capabilities mobile) (load 0.5))
     (aspace far (position 3000 3000 0) (capabilities mobile) (load 0.5))
     (aspace spare (position 6000 6000 0) (capabilities mobile) (load 0.5))
     (aspace quiet (position 0 0 0) (load 0.1)))
   `(("code.scm" . ,lab-code))))

(define pids
  (map (lambda (uid) (cons uid (start-lab-aspace! lab uid)))
       '(poser near far spare quiet)))
(join-lab (test-lab-file lab) 'tester)

(define (lab-proc name) (eval name (lab-environment)))
(define (at uid name) (remote-apply (uid->aspace uid) (lab-proc name)))
(define (spins-at uid)
  (remote-apply (uid->aspace uid) (eval '(lambda () spins) (lab-environment))))
(define (stopped-at? uid)
  (remote-apply (uid->aspace uid) (eval '(lambda () stopped) (lab-environment))))
(define (all-free?) ((lab-proc 'free-everywhere?) '(mobile)))
;; How often components' setup and cleanup ran on uid since it was last
;; asked: (INS OUTS).
(define (counts-at uid)
  (remote-apply (uid->aspace uid)
                (eval '(lambda ()
                         (let ((c (list ins outs))) (set! ins 0) (set! outs 0) c))
                      (lab-environment))))
;; The same, once a component stopped from outside has run its cleanup,
;; and a moment after, when a second setup and cleanup would have run.
(define (counts-after-stop uid)
  (wait-until 5 (lambda ()
                  (positive? (remote-apply (uid->aspace uid)
                                           (eval '(lambda () outs) (lab-environment))))))
  (thread-sleep! 0.5)
  (counts-at uid))
(define near-first (location-metric-maker '(0 0 0 0)))
(define (state-of task k) (status-state (list-ref (task-status task) (- k 1))))
(define (attempts-of task k) (status-attempts (list-ref (task-status task) (- k 1))))
;; Waits until component k of task runs on uid and has called out there.
(define (running-on? task k uid)
  (let ((before (spins-at uid)))
    (wait-until 10 (lambda ()
                     (and (equal? (list-head (state-of task k) 2) (list 'running uid))
                          (> (spins-at uid) before))))))
(define (list-head ls n)
  (if (or (zero? n) (null? ls)) '() (cons (car ls) (list-head (cdr ls) (- n 1)))))

(test-begin "task life cycle")

(test-group "start-task answers at once, and task-wait as pose-task would"
  (let ((t (start-task 'who 2 (list '((mobile) ()) '((mobile) ()))
                       (list near-first near-first)
                       (list (lab-proc 'who-am-i) (lab-proc 'who-am-i)))))
    (test-assert "a task record" (task? t))
    (test "its components negotiate or run meanwhile" #t
      (every (lambda (s) (and (memq (car (status-state s)) '(negotiating running)) #t))
             (task-status t)))
    (test "task-wait gives the results" '(near far) (task-wait t 10))
    (test "task-status tells each component by its number" '(1 2)
      (map status-index (task-status t)))
    (test "each one's setup and cleanup ran once" '((1 1) (1 1))
      (list (counts-at 'near) (counts-at 'far)))
    (test "each is done, with its value" '((done near) (done far))
      (list (state-of t 1) (state-of t 2)))
    (test-assert "tasks lists it" (assq 'posed (tasks)))
    (test "every subject is free" #t (all-free?))))

(test-group "an ordinary error is reported as pose-task reports it"
  (let ((t (start-task 'breaks 1 (list '((mobile) ())) (list near-first)
                       (list (lab-proc 'fail)) '(1) '(#t))))
    (let ((r (task-wait t 10)))
      (test "(error UID WHY), even when restartable" '(error near)
        (list (car (car r)) (cadr (car r))))
      (test "failed, tried once" 1 (length (attempts-of t 1)))
      (test "its setup and cleanup ran once" '(1 1) (counts-at 'near)))))

(test-group "task-wait with a timeout"
  (let ((t (start-task 'spinner 1 (list '((mobile) ())) (list near-first)
                       (list (lab-proc 'spin)))))
    (test-assert "raises, naming the task"
      (text-contains? (error-text (lambda () (task-wait t 0.2))) "not done within"))
    (test "then the task ends by itself" '(near) (task-wait t 20))))

(test-group "cancel-task"
  (counts-at 'near)
  (let ((t (start-task 'cancelled 1 (list '((mobile) ())) (list near-first)
                       (list (lab-proc 'spin-long)))))
    (test-assert "it runs on near" (running-on? t 1 'near))
    (test "the lab's status shows it, where it was posed and where it runs"
        (list (list 'posed (task-id t) 'running) (list 'running (task-id t) 1 'tester))
      (let ((status (lab-status (current-lab))))
        (list (let ((e (find (lambda (x) (eq? (cadr x) (task-id t)))
                             (list-ref (assq 'tester status) 5))))
                (list (car e) (listed-id e) (listed-state e)))
              (find (lambda (x) (eq? (cadr x) (task-id t)))
                    (list-ref (assq 'near status) 5)))))
    (test "cancel-task answers #t" #t (cancel-task t))
    (test "the component stops on its robot within a second" #t
      (wait-until 1 (lambda () (stopped-at? 'near))))
    (test "its setup and cleanup ran once" '(1 1) (counts-after-stop 'near))
    (test-assert "task-wait answers, the component cancelled"
      (let ((r (task-wait t 5)))
        (and (eq? (car (car r)) 'error) (equal? (state-of t 1) '(cancelled)))))
    (test "every subject is free" #t (wait-until 5 all-free?))))

(define (restart-robot! uid)
  (kill-process! (cdr (assq uid pids)))
  (revive! uid))

;; Starts uid again, and waits until this address space counts it live.
(define (revive! uid)
  (set! pids (cons (cons uid (start-lab-aspace! lab uid)) pids))
  (wait-until 5 (lambda () (memq uid (live-uids)))))

(test-group "a lost robot's restartable component goes to another"
  (let ((t (start-task 'moved 1 (list '((mobile) ())) (list near-first)
                       (list (lab-proc 'spin)) '(1) '(#t))))
    (test-assert "it runs on near" (running-on? t 1 'near))
    (kill-process! (cdr (assq 'near pids)))
    (let ((r (task-wait t 30)))
      (test "it ends on the next robot by the metric" '(far) r)
      (test "the status records each attempt"
          '((near lost) (far done))
        (map (lambda (a) (list (car a) (cadr a))) (attempts-of t 1))))
    (revive! 'near)
    (test "every subject is free" #t (wait-until 5 all-free?))))

(test-group "a lost robot's component that may not restart fails"
  (let ((t (start-task 'not-moved 1 (list '((mobile) ())) (list near-first)
                       (list (lab-proc 'spin)))))
    (test-assert "it runs on near" (running-on? t 1 'near))
    (restart-robot! 'near)
    (let ((r (task-wait t 30)))
      (test "(error near WHY)" '(error near) (list (car (car r)) (cadr (car r))))
      (test "tried once" 1 (length (attempts-of t 1))))))

(test-group "no orphans: a component whose poser dies stops"
  (counts-at 'near)
  (at 'poser 'start-spinning)
  (test "it runs on near" #t (wait-until 10 (lambda () (> (spins-at 'near) 0))))
  (kill-process! (cdr (assq 'poser pids)))
  (test "within two heartbeats and a little, it stops" #t
    (wait-until 5 (lambda () (stopped-at? 'near))))
  (test "its setup and cleanup ran once" '(1 1) (counts-after-stop 'near))
  (test "and its subjects are free" #t (wait-until 5 all-free?)))

(test-group "no ghosts: a frozen robot, declared lost, stops its component"
  (restart-robot! 'near)
  (let* ((near-pid (cdr (assq 'near pids)))
         (t (start-task 'ghost 1 (list '((mobile) ())) (list near-first)
                        (list (lab-proc 'spin-long)) '(1) '(#t))))
    (test-assert "it runs on near" (running-on? t 1 'near))
    (kill near-pid signal/stop)
    (test-assert "the component goes to far" (running-on? t 1 'far))
    (kill near-pid signal/continue)
    (test "near, back, stops its stale copy" #t
      (wait-until 5 (lambda () (stopped-at? 'near))))
    (test "whose setup and cleanup ran once" '(1 1) (counts-after-stop 'near))
    (let ((before (spins-at 'near)))
      (thread-sleep! 0.5)
      (test "and runs it no more" before (spins-at 'near)))
    (cancel-task t)
    (task-wait t 10)
    (test "every subject is free" #t (wait-until 5 all-free?))))

(test-group "no robot runs two exclusive components at once"
  ;; Six one-component tasks at once, from two threads, for three robots;
  ;; each component counts, on its robot, how many run there together.
  (let* ((start (lambda ()
                  (start-task 'crowd 1 (list '((mobile) ())) (list #f)
                              (list (lab-proc 'crowd)) '(1) '(#t))))
         (ts (append-map (lambda (batch)
                           (map (lambda (i) (start)) (iota 3)))
                         '(1 2))))
    (for-each (lambda (t) (task-wait t 60)) ts)
    (test "at most one at a time on each robot, seen from inside" '(1 1 1)
      (map (lambda (uid)
             (remote-apply (uid->aspace uid)
                           (eval '(lambda () (max most-inside 1)) (lab-environment))))
           '(near far spare)))
    (test "every subject is free" #t (wait-until 5 all-free?))))

(test-group "wrong arguments"
  (test-assert "restartable is checked"
    (text-contains? (error-text (lambda () (start-task 'x 1 (list '((mobile) ()))
                                                       (list #f) (list (lab-proc 'spin))
                                                       '(1) '(yes))))
                    "restartable"))
  (test-assert "task-status wants a task"
    (text-contains? (error-text (lambda () (task-status 42))) "not a task"))
  (test-assert "or the id of a task handed to the lab"
    (text-contains? (error-text (lambda () (task-status 'x))) "no such task")))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
