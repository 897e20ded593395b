;;; One truth about a task: for each way a task can end -- done, a
;;; component that failed, cancelled, past its deadline, nobody capable
;;; -- the same word in task-state, (tasks), task-status, pose-task's
;;; progress, the lab's status, the live view's table, and `murdoch
;;; pose`'s last line and exit code.  Workstations stand in for robots.
(import (except (scheme base) lambda define) (scheme write) (scheme eval) (scheme file)
        (scheme process-context) (srfi 1)
        (srfi 18) (chibi test)
        (only (chibi process) system)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch view)
        (murdoch testing harness))

(define lab-code "
(define (ok-job) 'ok)
(define (bad-job) (error \"bolt sheared\"))
;; A component that runs until its gate opens, calling its poser as it
;; waits: a call is where a cancelled component stops.
(define gates '())
(define (open-gate! gate) (set! gates (cons gate gates)))
(define (gated gate)
  (lambda ()
    (let loop ()
      (if (not (memq gate gates))
          (begin (remote-apply (uid->aspace 'tester) (lambda () #t))
                 (thread-sleep! 0.05)
                 (loop))))
    gate))
")

(define lab
  (make-test-lab
   '((code "code.scm") (heartbeat 0.2)
     (aspace tester)
     (aspace w1 (capabilities lift))
     (aspace w2 (capabilities lift)))
   `(("code.scm" . ,lab-code))))

(define pids
  (map (lambda (uid) (cons uid (start-lab-aspace! lab uid))) '(w1 w2)))
(join-lab (test-lab-file lab) 'tester)
(wait-until 10 (lambda () (= 2 (length (filter (lambda (u) (memq u '(w1 w2)))
                                               (live-uids))))))

(define (lab-proc name) (eval name (lab-environment)))
(define (open-gate! uid gate)
  (remote-apply (uid->aspace uid) (lab-proc 'open-gate!) gate))

(define lift '((lift) ()))

;; A task of n lift components running procs, started with options,
;; its progress written to the string port out.
(define (start out procs . options)
  (parameterize ((pose-task-progress out))
    (apply start-task 'job (length procs) (map (lambda (p) lift) procs)
           (map (lambda (p) #f) procs) procs options)))

;; Holds both workstations until their gates open.
(define (block-both! gate)
  (let ((t (start (open-output-string) (list (lab-proc `(gated ',gate))
                                              (lab-proc `(gated ',gate))))))
    (wait-until 10 (lambda () (eq? (task-state t) 'running)))
    t))

;; The word task-status's entries give: done when every component is,
;; else cancelled or deadline when one says so, else failed.
(define (status-word t)
  (let ((states (map (lambda (s) (car (status-state s))) (task-status t))))
    (cond ((every (lambda (s) (eq? s 'done)) states) 'done)
          ((memq 'cancelled states) 'cancelled)
          ((memq 'deadline states) 'deadline)
          (else 'failed))))

(define (last-line text)
  (let ((lines (remove (lambda (l) (string=? l "")) (text-lines text))))
    (if (pair? lines) (last lines) "")))

(define (status-text)
  (let ((out (open-output-string)))
    (show-status out)
    (get-output-string out)))

;; The live view's table of tasks, and a look at this address space, the
;; poser, as the view looks.  The view shows the tasks it saw begin: each
;; test looks as soon as it has started its task, before the task's own
;; thread has run.
(define table (make-task-table))
(define looks 0)
(define (look!)
  (set! looks (+ looks 1))
  (task-table-update! table looks (list (list 'tester (aspace-report)
                                              (filter listed-posed? (tasks))))))

;; The state the live view's table gives t.
(define (view-state t)
  (look!)
  (let ((entry (find (lambda (e) (equal? (cdr (assq 'id e))
                                         (symbol->string (task-id t))))
                     (vector->list (task-table->json table 50)))))
    (and entry (cdr (assq 'state entry)))))

;; What a person reads for t: its word, and why for a failed one.
(define (word-text t)
  (if (eq? (task-state t) 'failed)
      (string-append "failed: " (task-why t))
      (symbol->string (task-state t))))

;; Every view of the task t, which ended, as the word it shows.
(define (check-all! label t word out)
  (test (string-append label ": task-state") word (task-state t))
  (test (string-append label ": (tasks)") word
    (listed-state (find (lambda (e) (eq? (listed-id e) (task-id t))) (tasks))))
  (test (string-append label ": task-status") word (status-word t))
  (test (string-append label ": pose-task's progress, last")
      (string-append "pose-task: " (symbol->string (task-id t)) ": " (word-text t))
    (last-line (get-output-string out)))
  (test (string-append label ": the lab's status") #t
    (text-contains? (status-text)
                    (string-append "task " (symbol->string (task-id t)) " "
                                   (word-text t))))
  (test (string-append label ": the live view") (word-text t) (view-state t)))

(test-begin "one truth about a task")

(test-group "done: every component completed"
  (let* ((out (open-output-string))
         (t (start out (list (lab-proc 'ok-job) (lab-proc 'ok-job)))))
    (look!)
    (test "its results" '(ok ok) (task-wait t 10))
    (check-all! "done" t 'done out)))

(test-group "failed: one component raised, the other completed"
  (let* ((out (open-output-string))
         (t (start out (list (lab-proc 'ok-job) (lab-proc 'bad-job)))))
    (look!)
    (task-wait t 10)
    (check-all! "failed" t 'failed out)
    (test "why: the first failure's" #t (text-contains? (task-why t) "bolt sheared"))
    (test "pose-task's progress says the component failed, and why" #t
      (any (lambda (l) (and (text-contains? l "component 2 failed on w")
                            (text-contains? l "bolt sheared")))
           (text-lines (get-output-string out))))))

(test-group "cancelled while it runs"
  (let* ((out (open-output-string))
         (t (start out (list (lab-proc '(gated 'never))))))
    (look!)
    (wait-until 10 (lambda () (eq? (task-state t) 'running)))
    (cancel-task t)
    (task-wait t 10)
    (check-all! "cancelled" t 'cancelled out)
    (test "a task over stays as it ended: cancelling it again changes nothing"
        'cancelled (begin (cancel-task t) (task-state t)))))

(test-group "deadline, while it waits"
  (let* ((blocker (block-both! 'b1))
         (out (open-output-string))
         (t (start out (list (lab-proc 'ok-job)) 'wait #t 'deadline 0.5)))
    (look!)
    (test "task-wait answers deadline" 'deadline (task-wait t 10))
    (check-all! "deadline" t 'deadline out)
    (for-each (lambda (uid) (open-gate! uid 'b1)) '(w1 w2))
    (task-wait blocker 10)))

(test-group "failed: nobody is capable"
  (let* ((out (open-output-string))
         (t (parameterize ((pose-task-progress out))
              (start-task 'fly 1 (list '((wings) ())) (list #f) (list (lab-proc 'ok-job))))))
    (look!)
    (test "task-wait answers not-enough-takers" 'not-enough-takers (task-wait t 10))
    (check-all! "not-enough-takers" t 'failed out)))

(test-group "a task done is still done when cancelled after"
  (let ((t (start (open-output-string) (list (lab-proc 'ok-job)))))
    (task-wait t 10)
    (cancel-task t)
    (test "done" 'done (task-state t))))

;; murdoch pose, a guest of the lab: its exit code and last line.  It is
;; waited for without blocking this process, which is an address space
;; of the lab that the pose talks to.
(define (pose file text)
  (let* ((in-lab (lambda (name) (string-append (test-lab-directory lab) "/" name)))
         (task (in-lab file))
         (out (in-lab (string-append file ".out")))
         (code (in-lab (string-append file ".code"))))
    (call-with-output-file task (lambda (port) (write-string text port)))
    (let ((pid (start-process! (list "sh" "-c" "\"$@\"; echo $? >\"$0.new\"; mv \"$0.new\" \"$0\"" code
                                     (tool-path "bin/murdoch") "pose" (test-lab-file lab)
                                     task)
                               out)))
      (wait-until 60 (lambda () (and (file-exists? code) (pair? (read-lines code)))))
      (reap! pid)
      (list (string->number (car (read-lines code))) (last-line (file-text out))))))

(define (pose-says? answer code word)
  (and (= (car answer) code)
       (text-contains? (cadr answer) "murdoch pose: ")
       (text-contains? (cadr answer) (string-append " " word))))

(test-group "murdoch pose: its last line and exit code"
  (test "done: exit 0" #t
    (pose-says? (pose "done.scm" "(list 'job 1 (list '((lift) ())) (list #f) (list ok-job))")
                0 "done"))
  (test "failed: exit 1, with why" #t
    (pose-says? (pose "failed.scm" "(list 'job 1 (list '((lift) ())) (list #f) (list bad-job))")
                1 "failed: bolt sheared"))
  (let ((blocker (block-both! 'b2)))
    (test "deadline: exit 1" #t
      (pose-says? (pose "late.scm"
                        "(start-task 'job 1 (list '((lift) ())) (list #f) (list ok-job) 'wait #t 'deadline 0.5)")
                  1 "deadline"))
    (for-each (lambda (uid) (open-gate! uid 'b2)) '(w1 w2))
    (task-wait blocker 10))
  (test "nobody capable: exit 1" #t
    (pose-says? (pose "fly.scm" "(list 'fly 1 (list '((wings) ())) (list #f) (list ok-job))")
                1 "failed: not-enough-takers")))

(test-group "finished tasks are kept boundedly: tasks-kept (20 by default)"
  (for-each (lambda (i) (task-wait (start (open-output-string) (list (lab-proc 'ok-job))) 10))
            (iota 25))
  (test "(tasks) lists 20 tasks over, no more" 20
    (count (lambda (e) (and (listed-posed? e)
                            (memq (listed-state e) '(done failed cancelled deadline))))
           (tasks))))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
