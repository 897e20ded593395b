;;; Robot failures of simulated robots, in a lab the simulator runs: a base
;;; that stalls against a wall, and a trip server that dies, are robot
;;; failures, which move a restartable component to another robot or fail
;;; it as lost; they are not the component's own errors.
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (srfi 1) (srfi 18) (chibi test)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness))

(define lab-code "
;; Setup and cleanup count, here, how often they run.
(define ins 0)
(define outs 0)
;; Drives a metre ahead: moseley meets the wall in front of it.
(define (drive)
  (dynamic-wind (lambda () (set! ins (+ ins 1)))
                (lambda () (translate 1000) (local-aspace-uid))
                (lambda () (set! outs (+ outs 1)))))
;; Reads its odometry until stopped.
(define (watch)
  (let loop ((n 400)) (reckon) (thread-sleep! 0.05) (if (> n 0) (loop (- n 1)) 'watched)))
")

(define lab
  (make-test-lab
   '((code "code.scm") (heartbeat 0.3)
     (aspace tester)
     (aspace moseley (robot (pose 0 0 0)) (capabilities mobile))
     (aspace ernst (robot (pose 0 2000 0)) (capabilities mobile))
     (world (wall 500 -1000 500 1000)
            (wall -4000 -4000 4000 -4000) (wall 4000 -4000 4000 4000)
            (wall 4000 4000 -4000 4000) (wall -4000 4000 -4000 -4000))
     (simulator (speed 4)))
   `(("code.scm" . ,lab-code))))

;; The simulator, alone, so that killing it kills only the robots' trip
;; servers; then the robots' address spaces.
(define sim-out (string-append (test-lab-directory lab) "/b14.out"))
(define sim-pid
  (start-process! (list (tool-path "sim/b14") (test-lab-file lab)
                        "--port-base" (number->string (test-lab-port-base lab))
                        "--lock-dir" (test-lab-directory lab))
                  sim-out))
(wait-until 30 (lambda () (text-contains? (file-text sim-out) "b14: ready")))
(for-each (lambda (uid) (start-lab-aspace! lab uid)) '(moseley ernst))
(join-lab (test-lab-file lab) 'tester)

(define (lab-proc name) (eval name (lab-environment)))
;; moseley first, by name.
(define moseley-first (metric-by (lambda (uid) (if (eq? uid 'moseley) 0 1))))
(define (attempts-of t) (status-attempts (car (task-status t))))

(test-begin "robot failures")

(test-group "a stalled base is a robot failure"
  (let* ((t (start-task 'drive 1 (list '((mobile) ())) (list moseley-first)
                        (list (lab-proc 'drive)) '(1) '(#t)))
         (r (task-wait t 60)))
    (test "the component moves to ernst, which drives its metre" '(ernst) r)
    (test "moseley is recorded as lost, not as failed" '(moseley lost)
      (let ((a (car (attempts-of t)))) (list (car a) (cadr a))))
    (test "the component's setup and cleanup ran once on each" '((1 1) (1 1))
      (map (lambda (uid)
             (remote-apply (uid->aspace uid)
                           (eval '(lambda () (list ins outs)) (lab-environment))))
           '(moseley ernst)))))

(test-group "a trip server that dies is a robot failure"
  (let ((t (start-task 'watch 1 (list '((mobile) ())) (list moseley-first)
                       (list (lab-proc 'watch)))))
    (wait-until 20 (lambda () (eq? (car (status-state (car (task-status t)))) 'running)))
    (thread-sleep! 0.5)
    ;; Every robot's trip connection closes; their address spaces live on.
    (kill-process! sim-pid)
    (let ((r (task-wait t 30)))
      (test "not restartable: it fails" 'error (car (car r)))
      (test "as lost, its robot having failed" 'lost
        (cadr (car (attempts-of t))))
      (test-assert "for its trip connection, which the robot said"
        (text-contains? (car (cddr (car (attempts-of t)))) "reckon")))))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
