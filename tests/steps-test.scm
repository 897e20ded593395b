;;; Tasks of several steps, and a team's synchronization inside a step,
;;; between real address spaces.  The components write what they do to a
;;; record kept on quiet, so the order is seen from inside them.
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (srfi 1) (srfi 18) (chibi test)
        (only (chibi process) kill signal/stop signal/continue)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness))

(define lab-code "
(define record '())
(define (note! x) (set! record (cons x record)))
(define (tell! what)
  (remote-apply (uid->aspace 'quiet) (lambda () (note! (list what (local-aspace-uid))))))
;; A step's component: tells when it starts and ends, and answers its uid.
(define (work previous)
  (tell! 'start) (thread-sleep! 0.3) (tell! 'end) (local-aspace-uid))
;; Answers what the step before answered.
(define (echo previous) previous)
;; Waits at the barrier meet; the second of the team comes late.
(define (meet previous)
  (if (eq? (local-aspace-uid) (cadr (current-team))) (thread-sleep! 0.5))
  (tell! 'before)
  (team-barrier 'meet 10)
  (tell! 'after)
  #t)
;; The first member sends its uid to the second, which answers what came.
(define (pass previous)
  (if (eq? (local-aspace-uid) (car (current-team)))
      (begin (team-send! (cadr (current-team)) 'hello) 'sent)
      (team-receive 10)))
;; Waits for a member that never comes.
(define (wait-alone previous)
  (if (eq? (local-aspace-uid) (car (current-team)))
      (team-barrier 'never 1)
      'left))
(define (free-everywhere? subjects)
  (every (lambda (r) (every (lambda (s) (null? (cadr s))) (cadr r)))
         (request 'all (lambda ()
                         (filter-map (lambda (t)
                                       (let ((s (topic-status t))) (and s (list t s))))
                                     subjects)))))
")

(define lab
  (make-test-lab
   '((code "code.scm") (heartbeat 0.3)
     (aspace tester)
     (aspace near (position 100 100 0) (capabilities mobile wheels) (load 0.5))
     (aspace far (position 3000 3000 0) (capabilities mobile wheels) (load 0.5))
     (aspace quiet (position 0 0 0) (load 0.1))
     (aspace spare (position 9000 9000 0) (capabilities wheels) (load 0.5)))
   `(("code.scm" . ,lab-code))))

(define pids
  (map (lambda (uid) (cons uid (start-lab-aspace! lab uid))) '(near far quiet spare)))
(join-lab (test-lab-file lab) 'tester)

(define (lab-proc name) (eval name (lab-environment)))
(define (record) (reverse (remote-apply (uid->aspace 'quiet)
                                        (eval '(lambda () record) (lab-environment)))))
(define (clear-record!)
  (remote-apply (uid->aspace 'quiet)
                (eval '(lambda () (set! record '())) (lab-environment))))
(define (all-free?) ((lab-proc 'free-everywhere?) '(mobile near far)))
(define near-first (location-metric-maker '(0 0 0 0)))
(define far-first (location-metric-maker '(3000 3000 0 0)))
(define two '(((mobile) ()) ((mobile) ())))
(define (kinds-in-order rec) (map car rec))

(test-begin "tasks of steps")

(test-group "steps run in order, each after the one before is done"
  (clear-record!)
  (let ((r (pose-steps 'two-steps
                       (task-step two (list near-first far-first)
                                  (list (lab-proc 'work) (lab-proc 'work)))
                       (task-step two (list far-first near-first)
                                  (list (lab-proc 'work) (lab-proc 'echo))))))
    (test "each step's results; the second sees the first's"
        '((near far) (far (near far))) r)
    (let ((rec (record)))
      (test "both ends of step 1 come before step 2 starts"
          '(start start end end start end) (kinds-in-order rec)))
    (test "every subject is free" #t (wait-until 5 all-free?))))

(test-group "a component may ask for the robot of an earlier one"
  (let ((r (pose-steps 'keep
                       (task-step '(((mobile) ())) (list far-first)
                                  (list (lab-proc 'work)))
                       (task-step '((same 1 1)) (list near-first)
                                  (list (lab-proc 'work))))))
    (test "(same 1 1) gets far again, though near is nearer" '((far) (far)) r)))

(test-group "a team barrier"
  (clear-record!)
  (let ((r (pose-steps 'meet (task-step two (list near-first far-first)
                                        (list (lab-proc 'meet) (lab-proc 'meet))))))
    (test "both come through" '((#t #t)) r)
    (test "nobody is after it before everyone is before it"
        '(before before after after) (kinds-in-order (record)))))

(test-group "values passed by uid through the team"
  (test "the second member receives what the first sent, and from whom"
      '((sent (near . hello)))
    (pose-steps 'pass (task-step two (list near-first far-first)
                                 (list (lab-proc 'pass) (lab-proc 'pass))))))

(test-group "a barrier whose member never comes"
  (let* ((t (start-steps 'alone
                         (task-step two (list near-first far-first)
                                    (list (lab-proc 'wait-alone) (lab-proc 'wait-alone)))
                         (task-step two (list near-first far-first)
                                    (list (lab-proc 'work) (lab-proc 'work)))))
         (r (task-wait t 30)))
    (test "the waiting member fails with a timeout naming the missing one"
        #t (and (eq? (car (car (car r))) 'error)
                (text-contains? (car (cddr (car (car r)))) "timed out waiting for")
                (text-contains? (car (cddr (car (car r)))) "far")))
    (test "the task stops after the failed step" 1 (length r))
    (test "and says so" '(#t failed)
      (let ((e (find (lambda (e) (eq? (listed-id e) (task-id t))) (tasks))))
        (list (listed-posed? e) (listed-state e))))
    (test "task-status tells the step it started, by its number" '(1)
      (map step-status-index (task-status t)))
    (test "every subject is free" #t (wait-until 5 all-free?))))

;; far does component 2 at once, then takes component 1 when near is lost;
;; lost there too, it gives component 1 to spare and stays the robot of
;; component 2, which step 2 asks for again.  A robot is lost here by
;; freezing its process (SIGSTOP) until its silence is noticed.
(test-group "a robot twice in a team is replaced only where it was lost"
  (let* ((hold (lambda (previous)
                 (let loop ((n 40))
                   (if (> n 0) (begin (thread-sleep! 0.1) (loop (- n 1)))))
                 (local-aspace-uid)))
         (t (start-steps 'twice
                         (task-step '(((wheels) ()) ((wheels) ()))
                                    (list near-first far-first)
                                    (list hold (lambda (previous) (local-aspace-uid)))
                                    '(2 1) '(#t #f))
                         (task-step '((same 1 1) (same 1 2)) '(#f #f)
                                    (list (lambda (previous) (local-aspace-uid))
                                          (lambda (previous) (local-aspace-uid))))))
         ;; The robot component 1 of step 1 runs on, or #f.
         (runs-1 (lambda ()
                   (let ((steps (task-status t)))
                     (and (pair? steps) (pair? (step-status-entries (car steps)))
                          (let ((state (status-state
                                        (car (step-status-entries (car steps))))))
                            (and (eq? 'running (car state)) (cadr state)))))))
         (freeze-until-moved!
          (lambda (uid)
            (wait-until 10 (lambda () (eq? uid (runs-1))))
            (kill (cdr (assq uid pids)) signal/stop)
            (wait-until 10 (lambda ()
                             (let ((now (runs-1))) (and now (not (eq? uid now))))))
            (kill (cdr (assq uid pids)) signal/continue))))
    (freeze-until-moved! 'near)
    (freeze-until-moved! 'far)
    (test "step 2 runs on the robots step 1 ended with: spare, and far"
        '((spare far) (spare far))
      (let ((r (task-wait t 60))) (list (car r) (cadr r))))))

(test-group "wrong arguments"
  (test-assert "(same J K) must name an earlier step"
    (text-contains?
     (error-text (lambda () (start-steps 'x (task-step '((same 1 1)) '(#f)
                                                      (list (lab-proc 'work))))))
     "same J K")))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
