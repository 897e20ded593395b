;;; A line longer than one look tells (lib/murdoch/task/waiting.scm,
;;; told-now): a poser with more tasks waiting than a look tells looks
;;; at the best of them every time and at the rest in turn, so that every
;;; task, the last included, is told its place, one place each, 1 to n;
;;; the robot freed goes to the first, and cancelling the rest frees all.
;;; The number of tasks is drawn, seeded, between three and four looks'
;;; worth.
;;; tests/run: long
(import (except (scheme base) lambda define) (scheme eval) (srfi 1) (srfi 27)
        (chibi test)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness))

(define lab-code "
(define open-gates '())
(define (open-gate! gate) (set! open-gates (cons gate open-gates)))
(define (job gate)
  (lambda ()
    (let loop ()
      (if (and gate (not (memq gate open-gates)))
          (begin (thread-sleep! 0.05) (loop))))
    gate))
")

(define n-tasks
  (begin (random-source-pseudo-randomize! default-random-source 43 1)
         (+ 100 (random-integer 30))))

(define lab
  (make-test-lab
   `((code "code.scm") (heartbeat 0.2) (max-waiting ,(+ n-tasks 10))
     (aspace tester)
     (aspace r1 (capabilities arm)))
   `(("code.scm" . ,lab-code))))

(define pids (map (lambda (uid) (cons uid (start-lab-aspace! lab uid))) '(r1)))
(join-lab (test-lab-file lab) 'tester)
(wait-until 10 (lambda () (memq 'r1 (live-uids))))

(define (lab-proc name) (eval name (lab-environment)))
(define (job gate) ((lab-proc 'job) gate))
(define (state-of t) (status-state (car (task-status t))))
(define (place-of t)
  (let ((s (state-of t))) (and (eq? (car s) 'waiting) (cadr s))))

(test-begin "a line longer than a look")

(let* ((block (start-task 'block 1 (list '((arm) ())) (list #f) (list (job 'g))))
       (_ (wait-until 10 (lambda () (eq? (car (state-of block)) 'running))))
       (line (map (lambda (i)
                    (start-task 'job 1 (list '((arm) ())) (list #f) (list (job #f))
                                'wait #t))
                  (iota n-tasks))))
  (test-assert (string-append "every one of " (number->string n-tasks)
                              " tasks waiting is told a place, the last too")
    (wait-until 60 (lambda () (every place-of line))))
  (test "one place each, 1 to n, in the order posed" (iota n-tasks 1)
    (begin (wait-until 60 (lambda () (equal? (map place-of line) (iota n-tasks 1))))
           (map place-of line)))
  (remote-apply (uid->aspace 'r1) (lab-proc 'open-gate!) 'g)
  (test "the robot freed goes to the first" (list #f) (task-wait (car line) 30))
  (for-each cancel-task (cdr line))
  (test "the rest, cancelled, end cancelled" '(cancelled)
    (begin (for-each (lambda (t) (task-wait t 30)) (cdr line))
           (delete-duplicates (map task-state (cdr line)))))
  (test "no task waits" '()
    (append-map cadr (request 'waiting-tasks waiting-ranks)))
  (test-assert "no reservation is held"
    (wait-until 10 (lambda ()
                     (every (lambda (r) (every (lambda (s) (null? (cadr s))) (cadr r)))
                            (request-status 'arm))))))

(test-end)
