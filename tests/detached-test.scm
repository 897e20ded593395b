;;; Tasks handed to the lab, between real processes: a poser that leaves
;;; at once, a coordinator killed mid-task, while its task waits holding
;;; a robot, or together with its standby, and a robot lost while the
;;; standby is in charge.  Workstations stand in for robots, as in
;;; task-test; each component writes (begin TAG UID SECOND) and (end TAG
;;; UID SECOND) to its own address space's log, which the tests read.
;;; tests/run: long
(import (except (scheme base) lambda define) (scheme write) (scheme read) (scheme eval)
        (srfi 1) (srfi 18) (srfi 132) (chibi test)
        (only (chibi process) kill signal/stop signal/continue)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment)
        (murdoch cli command) (murdoch testing harness))

(define lab-code "
(define (tell . xs) (write (append xs (list (time->seconds (current-time))))) (newline)
  (flush-output-port))
;; A component that runs rounds of 50 ms, calling out each round, as a
;; robot command would go to its robot, so that it stops as an orphan.
(define (work tag rounds)
  (dynamic-wind
   (lambda () (tell 'begin tag (local-aspace-uid)))
   (lambda () (rounds! rounds) (local-aspace-uid))
   (lambda () (tell 'end tag (local-aspace-uid)))))
(define (rounds! n)
  (remote-apply (local-aspace) (lambda () #t))
  (thread-sleep! 0.05)
  (if (> n 0) (rounds! (- n 1))))
;; A member of a team of two: both meet; the first sends before to the
;; second and waits at mid while the second works rounds; past mid, the
;; first sends after-1 and after-2, the second takes all three; both meet
;; again at done.  Each tells (team TAG UID WHAT) of each call it made.
(define (teamwork tag rounds)
  (let* ((team (current-team)) (me (local-aspace-uid)) (first? (eq? me (car team)))
         (other (if first? (cadr team) (car team))))
    (define (told what) (tell 'team tag me what))
    (tell 'begin tag me)
    (team-barrier 'meet 60)
    (told 'met)
    (cond (first?
           (team-send! other 'before)
           (told 'sent)
           (team-barrier 'mid 60)
           (told 'mid)
           (team-send! other 'after-1)
           (team-send! other 'after-2))
          (else
           (rounds! rounds)
           (team-barrier 'mid 60)
           (told 'mid)
           (for-each (lambda (i) (told (list 'got (team-receive 60)))) '(1 2 3))))
    (team-barrier 'done 60)
    (told 'done)
    (tell 'end tag me)
    me))
(define (free-everywhere? subjects)
  (every (lambda (r) (every (lambda (s) (null? (cadr s))) (cadr r)))
         (request 'all (lambda ()
                         (filter-map (lambda (t)
                                       (let ((s (topic-status t))) (and s (list t s))))
                                     subjects)))))
")

(define robots '(r1 r2 r3))
(define coordinators '(c1 c2 c3))

(define lab
  (make-test-lab
   `((code "code.scm") (heartbeat 0.3) (lease 4)
     (aspace tester)
     (aspace poser)
     ,@(map (lambda (uid load) `(aspace ,uid (position 0 0 0) (load ,load)))
            coordinators '(0.1 0.2 0.3))
     ,@(map (lambda (uid i) `(aspace ,uid (position ,(* 1000 i) 0 0)
                                     (capabilities mobile) (load 0.5)))
            robots (iota 3)))
   `(("code.scm" . ,lab-code)
     ("survey.scm" . "(list 'survey 1 (list '((mobile) ())) (list #f)
                          (list (lambda () (work 'cli 60))))")
     ("long.scm" . "(list 'long 1 (list '((mobile) ())) (list #f)
                        (list (lambda () (work 'cancelled 2000))))"))))

(define pids
  (map (lambda (uid) (cons uid (start-lab-aspace! lab uid)))
       (append '(poser) coordinators robots)))
(join-lab (test-lab-file lab) 'tester)

(define (lab-proc name) (eval name (lab-environment)))
(define (all-free?) ((lab-proc 'free-everywhere?) '(mobile)))
(define (in-dir name) (string-append (test-lab-directory lab) "/" name))

;; Runs `bin/murdoch ARG ...` as a process of its own while this one
;; serves the lab, and answers its output, then "exit CODE".
(define commands-run 0)
(define (murdoch-status . args)
  (set! commands-run (+ commands-run 1))
  (let* ((out (in-dir (string-append "command-" (number->string commands-run))))
         (pid (start-process!
               (append (list "sh" "-c" "\"$@\"; echo \"exit $?\"" "murdoch"
                             (tool-path "bin/murdoch"))
                       args)
               out)))
    (wait-until 60 (lambda () (reaped-if-ended! pid)))
    (file-text out)))

;; Lines of uid's log that begin with (WORD TAG.
(define (log-lines uid word tag)
  (filter (lambda (line)
            (text-contains? line (string-append "(" word " " (symbol->string tag) " ")))
          (read-lines (in-dir (string-append (symbol->string uid) ".log")))))

;; The second at which each component tagged tag began, from the robots'
;; own logs, earliest first.
(define (begin-seconds tag)
  (list-sort < (append-map (lambda (r)
                             (map (lambda (line) (list-ref (read (open-input-string line)) 3))
                                  (log-lines r "begin" tag)))
                           robots)))

;; Task id's entry of lab-tasks; one that no address space answers for
;; now is (ID #f 0 #f #f #f #f #f).
(define (entry-of id)
  (or (find (lambda (e) (eq? (lab-task-id e) id)) (lab-tasks))
      (list id #f 0 #f #f #f #f #f)))

(define (coordinator-of id) (lab-task-coordinator (entry-of id)))

(define (running-everywhere? id)
  (every (lambda (s) (eq? (car (status-state s)) 'running)) (task-status id)))

;; The coordinator of task id once one has taken it over, or #f.
(define (second-coordinator id)
  (wait-until 10 (lambda ()
                   (let ((e (entry-of id)))
                     (and (eq? (lab-task-role e) 'coordinator)
                          (= 2 (lab-task-epoch e))
                          (lab-task-coordinator e))))))

;; Poses from the poser a detached task named tag, of one restartable
;; component of rounds, and answers its id once it runs, with a standby.
(define (running-detached tag rounds)
  (let ((id (remote-apply
             (uid->aspace 'poser)
             (eval `(lambda ()
                      (start-task ',tag 1 (list '((mobile) ())) (list #f)
                                  (list (lambda () (work ',tag ,rounds))) '(1) '(#t)
                                  'detach #t))
                   (lab-environment)))))
    (test-assert "it runs, with a standby"
      (wait-until 10 (lambda () (and (running-everywhere? id)
                                     (lab-task-standby (entry-of id))))))
    id))

;; Kills uid's process, as a crash would; restart! starts it again.
(define (kill! uid) (kill-process! (cdr (assq uid pids))))
(define (restart! uid)
  (set! pids (cons (cons uid (start-lab-aspace! lab uid))
                   (remove (lambda (p) (eq? (car p) uid)) pids))))

(test-begin "detached tasks")

(test-group "the poser leaves at once; another peer reads the results"
  (let* ((out (murdoch-status "pose" "--detach" (test-lab-file lab) (in-dir "survey.scm")))
         (id (string->symbol (car (text-lines out)))))
    (test "pose --detach exits 0, printing the task's id" #t (text-contains? out "exit 0"))
    (test-assert "the poser gone, its task runs"
      (wait-until 10 (lambda () (eq? 'running (lab-task-state (entry-of id))))))
    (test "its coordinator is the least loaded workstation" 'c1 (coordinator-of id))
    (test "and a standby on another" 'c2
      (wait-until 10 (lambda () (lab-task-standby (entry-of id)))))
    (let ((tasks (murdoch-status "tasks" (test-lab-file lab))))
      (test "murdoch tasks lists it, with its coordinator" #t
        (and (text-contains? tasks (symbol->string id))
             (text-contains? tasks "coordinator c1"))))
    (let ((waited (murdoch-status "wait" (test-lab-file lab) (symbol->string id))))
      (test "murdoch wait, a new peer, prints its result and exits 0" #t
        (and (text-contains? waited "exit 0")
             (any (lambda (r) (text-contains? waited (string-append "(" (symbol->string r) ")")))
                  robots))))
    (test "and task-wait from any peer reads it, kept" #t
      (and (memq (car (task-wait id 10)) robots) #t))
    (test "murdoch status shows it with its coordinator" #t
      (text-contains? (murdoch-status "status" (test-lab-file lab))
                      (string-append "coordinates detached task " (symbol->string id)))))
  (let* ((out (murdoch-status "pose" "--detach" (test-lab-file lab) (in-dir "long.scm")))
         (id (string->symbol (car (text-lines out)))))
    (test-assert "a long task runs"
      (wait-until 10 (lambda () (running-everywhere? id))))
    (test "murdoch cancel stops it" #t
      (text-contains? (murdoch-status "cancel" (test-lab-file lab) (symbol->string id))
                      "exit 0"))
    (test "its component ends on its robot" #t
      (wait-until 10 (lambda () (any (lambda (r) (pair? (log-lines r "end" 'cancelled)))
                                     robots))))
    (test-assert "and its state says so"
      (wait-until 10 (lambda () (equal? '(cancelled)
                                        (status-state (car (task-status id)))))))
    (test-assert "nothing is held" (wait-until 10 all-free?))))

(test-group "the coordinator killed mid-task: its standby takes over"
  (let ((id (remote-apply
             (uid->aspace 'poser)
             (eval '(lambda ()
                      (start-task 'killed 2 (list '((mobile) ()) '((mobile) ()))
                                  (list #f #f)
                                  (list (lambda () (work 'killed 80))
                                        (lambda () (work 'killed 80)))
                                  '(1 1) '(#t #t) 'detach #t))
                   (lab-environment)))))
    (test-assert "both components run" (wait-until 10 (lambda () (running-everywhere? id))))
    (test-assert "it has a standby"
      (wait-until 10 (lambda () (lab-task-standby (entry-of id)))))
    (let ((old (coordinator-of id)) (standby (lab-task-standby (entry-of id))))
      (kill! old)
      (test "the standby takes over" standby (second-coordinator id))
      (test-assert "and chooses a new standby"
        (wait-until 10 (lambda ()
                         (let ((s (lab-task-standby (entry-of id))))
                           (and s (not (memq s (list old standby))))))))
      (let ((results (task-wait id 30)))
        (test "the task completes, each component on a robot of its own" 2
          (length (delete-duplicates (filter (lambda (r) (memq r robots)) results))))
        (test "each component's own log shows one begin and one end" '((1 1) (1 1))
          (map (lambda (r) (list (length (log-lines r "begin" 'killed))
                                 (length (log-lines r "end" 'killed))))
               results))
        (test "nothing was reassigned" '(() ())
          (map (lambda (s) (remove (lambda (a) (eq? (cadr a) 'done)) (status-attempts s)))
               (task-status id))))
      (restart! old))))

(test-group "the coordinator killed mid-step: its standby takes the steps over"
  ;; Step 1 has one component, step 2 two, each handed step 1's results;
  ;; the coordinator of one task is killed in its step 1, of another in
  ;; its step 2.
  (define (tagged tag part)
    (string->symbol (string-append (symbol->string tag) part)))
  (define (steps-task tag)
    (remote-apply
     (uid->aspace 'poser)
     (eval `(lambda ()
              (start-steps ',tag
                           (task-step (list '((mobile) ())) (list #f)
                                      (list (lambda (previous)
                                              (work ',(tagged tag "-one") 60))))
                           (task-step (list '((mobile) ()) '((mobile) ())) (list #f #f)
                                      (list (lambda (previous)
                                              (list previous
                                                    (work ',(tagged tag "-two") 60)))
                                            (lambda (previous)
                                              (list previous
                                                    (work ',(tagged tag "-two") 60)))))
                           'detach #t))
           (lab-environment))))
  (define (in-step? id i)
    (let ((steps (task-status id)))
      (and (= i (length steps))
           (every (lambda (s) (eq? (car (status-state s)) 'running))
                  (step-status-entries (list-ref steps (- i 1)))))))
  (define (begins-and-ends tag)
    (map (lambda (r) (list r (length (log-lines r "begin" tag)) (length (log-lines r "end" tag))))
         robots))
  (for-each
   (lambda (tag step)
     (let ((id (steps-task tag)))
       (test-assert (string-append "step " (number->string step) " runs, with a standby")
         (wait-until 15 (lambda () (and (in-step? id step) (lab-task-standby (entry-of id))))))
       (let ((old (coordinator-of id)) (standby (lab-task-standby (entry-of id))))
         (kill! old)
         (test "the standby takes over" standby (second-coordinator id))
         (let* ((waited (murdoch-status "wait" (test-lab-file lab) (symbol->string id)))
                (results (task-wait id 30))
                (one (car (car results)))
                (two (map cadr (cadr results))))
           (test-assert "the task completes, read by a new peer, murdoch wait"
             (text-contains? waited "exit 0"))
           (test "step 1's result, and step 2's, each handed step 1's"
             (list (list one) (map (lambda (u) (list (list one) u)) two))
             (task-wait id 5))
           (test "step 1 ran once: one begin and one end, in its robot's own log"
             (list (list one 1 1))
             (filter (lambda (x) (> (+ (cadr x) (car (cddr x))) 0))
                     (begins-and-ends (tagged tag "-one"))))
           (test "step 2's two ran once each, on robots of their own"
             (filter-map (lambda (r) (and (memq r two) (list r 1 1))) robots)
             (filter (lambda (x) (> (+ (cadr x) (car (cddr x))) 0))
                     (begins-and-ends (tagged tag "-two"))))
           (test "murdoch wait prints both steps' results" #t
             (every (lambda (u) (text-contains? waited (symbol->string u)))
                    (cons one two))))
         (restart! old))))
   '(stepped-a stepped-b) '(1 2)))

(test-group "the coordinator killed while its task waits, holding"
  ;; r2 and r3 are busy, r3 for longer; the detached task needs two
  ;; robots and holds r1; a task posed after it, at its priority, waits
  ;; for one.  Its coordinator killed, the lab frees r1 at the lease, and
  ;; the standby's negotiation must take it again in the task's rank:
  ;; were the rank lost, the later task would start on r1 at once, not
  ;; on r3 once r2 has gone to the task.
  (let* ((busy (map (lambda (tag rounds)
                      (start-task 'busy 1 (list '((mobile) ()))
                                  (list (location-metric-maker '(2000 0 0 0)))
                                  (list (eval `(lambda () (work ',tag ,rounds))
                                              (lab-environment)))))
                    '(busy-a busy-b) '(200 300)))
         (_ (wait-until 10 (lambda () (every (lambda (t) (running-everywhere? t)) busy))))
         (id (remote-apply
              (uid->aspace 'poser)
              (eval '(lambda ()
                       (start-task 'holder 2 (list '((mobile) ()) '((mobile) ()))
                                   (list #f #f)
                                   (list (lambda () (work 'holder 10))
                                         (lambda () (work 'holder 10)))
                                   'hold #t 'detach #t))
                    (lab-environment)))))
    (test-assert "it holds a robot and waits for another, with a standby"
      (wait-until 10 (lambda () (let ((e (entry-of id)))
                                  (and (eq? (lab-task-state e) 'holding)
                                       (lab-task-standby e))))))
    (let ((later (start-task 'later 1 (list '((mobile) ())) (list #f)
                             (list (eval '(lambda () (work 'later 10)) (lab-environment)))
                             'wait #t))
          (old (coordinator-of id)))
      (test-assert "the task posed after it waits"
        (wait-until 10 (lambda () (eq? 'waiting (task-state later)))))
      (kill! old)
      (test-assert "its standby takes over"
        (wait-until 10 (lambda () (let ((c (coordinator-of id))) (and c (not (eq? c old)))))))
      (test-assert "and holds a robot again, the first given back at the lease"
        (wait-until 10 (lambda () (let ((e (entry-of id)))
                                    (and (= 2 (lab-task-epoch e))
                                         (eq? (lab-task-state e) 'holding))))))
      (let ((results (task-wait id 60)))
        (test "it completes on two robots" 2
          (length (delete-duplicates (filter (lambda (r) (memq r robots)) results)))))
      (task-wait later 60)
      (let ((holder (begin-seconds 'holder)) (after (begin-seconds 'later)))
        (test "each began once, in the robots' logs" '(2 1)
          (list (length holder) (length after)))
        (test "in its rank: no begin of the later task's before its components'" '()
          (filter (lambda (s) (< s (last holder))) after)))
      (for-each task-wait busy)
      (test-assert "nothing is held after" (wait-until 10 all-free?))
      (restart! old))))

(test-group "the coordinator killed between team calls: the team goes on with the new one"
  ;; Killed while the first member waits at the barrier mid and a letter
  ;; to the second waits for it: the barrier, that letter and those sent
  ;; after reach the standby that took over, each once.
  (let* ((id (remote-apply
              (uid->aspace 'poser)
              (eval '(lambda ()
                       (start-steps 'teamed
                                    (task-step (list '((mobile) ()) '((mobile) ()))
                                               (list #f #f)
                                               (list (lambda (previous) (teamwork 'teamed 60))
                                                     (lambda (previous) (teamwork 'teamed 60))))
                                    'detach #t))
                    (lab-environment))))
         (told (lambda (what)
                 (filter-map (lambda (r)
                               (and (any (lambda (line)
                                           (equal? what (list-ref (read (open-input-string line))
                                                                  3)))
                                         (log-lines r "team" 'teamed))
                                    r))
                             robots))))
    (test-assert "the first member has sent, and waits at mid; the second works"
      (wait-until 15 (lambda () (and (= 2 (length (told 'met))) (= 1 (length (told 'sent)))
                                     (lab-task-standby (entry-of id))))))
    (let ((old (coordinator-of id)) (standby (lab-task-standby (entry-of id))))
      (kill! old)
      (test "the standby takes over" standby (second-coordinator id))
      (let* ((results (car (task-wait id 60)))
             (first (car (told 'sent)))
             (second (find (lambda (r) (and (memq r results) (not (eq? r first)))) robots))
         (calls (lambda (r)
                  (map (lambda (line) (list-ref (read (open-input-string line)) 3))
                       (if r (log-lines r "team" 'teamed) '())))))
        (test "the task completes, its two members on robots of their own" 2
          (length (delete-duplicates (filter (lambda (r) (memq r robots)) results))))
        (test "each member's own log: one begin and one end" '((1 1) (1 1))
          (map (lambda (r) (list (length (log-lines r "begin" 'teamed))
                                 (length (log-lines r "end" 'teamed))))
               (list first second)))
        (test "the first member's team calls, each once, in order"
          '(met sent mid done) (calls first))
        (test "the second took the letter sent before the kill and those after, each once"
          (list 'met 'mid (list 'got (cons first 'before)) (list 'got (cons first 'after-1))
                (list 'got (cons first 'after-2)) 'done)
          (calls second)))
      (restart! old))))

(test-group "after a takeover, its first coordinator back: the id still finds the task"
  ;; The id names the member that first coordinated the task; killed and
  ;; started again, that member counts its own poses from 1 again.
  (let* ((id (running-detached 'renamed 2000))
         (old (coordinator-of id))
         (standby (lab-task-standby (entry-of id))))
    (test-assert "the id is the lab's kind, naming its first coordinator"
      (text-contains? (symbol->string id) (string-append "@" (symbol->string old) "/lab-")))
    (kill! old)
    (test "the standby takes over" standby (second-coordinator id))
    (restart! old)
    (let ((plain (remote-apply
                  (uid->aspace old)
                  (eval '(lambda ()
                           (task-id (start-task 'renamed 1 (list '((mobile) ())) (list #f)
                                                (list (lambda () (work 'plain 0))))))
                        (lab-environment)))))
      (test-assert "a task posed at the first coordinator, started again, has an id of its own"
        (and (symbol? plain) (not (eq? plain id)))))
    (test-assert "task-status by the id, from a peer: its component runs on"
      (running-everywhere? id))
    (let ((tasks (murdoch-status "tasks" (test-lab-file lab))))
      (test "murdoch tasks lists it under its id, with its new coordinator" #t
        (and (text-contains? tasks (symbol->string id))
             (text-contains? tasks (string-append "coordinator " (symbol->string standby))))))
    (test "murdoch cancel with the id cancels it" #t
      (text-contains? (murdoch-status "cancel" (test-lab-file lab) (symbol->string id))
                      "exit 0"))
    (test "its component ends on its robot, begun once" '(1 1)
      (let ((robot (wait-until 10 (lambda ()
                                    (find (lambda (r) (pair? (log-lines r "end" 'renamed)))
                                          robots)))))
        (if robot
            (list (length (log-lines robot "begin" 'renamed))
                  (length (log-lines robot "end" 'renamed)))
            '())))
    (test "murdoch wait with the id says it was cancelled" #t
      (let ((waited (murdoch-status "wait" (test-lab-file lab) (symbol->string id))))
        (and (text-contains? waited "cancelled") (text-contains? waited "exit 1"))))
    (test-assert "nothing is held after" (wait-until 10 all-free?))))

(test-group "the standby stalled: a peer's wait follows the task as it moves"
  ;; The standby frozen (SIGSTOP), its coordinator lets the task go and
  ;; nobody coordinates it until the standby wakes and takes it over.  A
  ;; peer's task-wait meanwhile waits on; its task-status, bounded, says
  ;; the task is moving, not that it failed.
  (let ((id (running-detached 'stalled 60)))
    (let* ((e (entry-of id)) (coordinator (lab-task-coordinator e))
           (standby (lab-task-standby e)) (pid (cdr (assq standby pids))))
      (kill pid signal/stop)
      (test-assert "its standby frozen, the coordinator lets the task go"
        (wait-until 10 (lambda () (eq? 'let-go (remote-apply (uid->aspace coordinator)
                                                             handed-role-of id)))))
      (let* ((asking (lambda (thunk)
                       (thread-start!
                        (make-thread (lambda () (guard (e ((error-object? e) (error-object-message e)))
                                                   (thunk)))))))
             (waited (asking (lambda () (task-wait id 60))))
             (status (asking (lambda () (task-status id)))))
        (thread-sleep! 7)
        (kill pid signal/continue)
        (test-assert "task-status says it is moving"
          (let ((s (thread-join! status))) (and (string? s) (text-contains? s "is moving"))))
        (test-assert "task-wait waits on, and answers once the standby has it"
          (pair? (thread-join! waited)))
        (test "the standby took it over" standby (coordinator-of id))))))

(test-group "coordinator and standby killed at once: the task fails clearly"
  (let ((id (remote-apply
             (uid->aspace 'poser)
             (eval '(lambda ()
                      (start-task 'orphaned 1 (list '((mobile) ())) (list #f)
                                  (list (lambda () (work 'orphaned 2000))) 'detach #t))
                   (lab-environment)))))
    (test-assert "it runs, with a standby"
      (wait-until 10 (lambda () (and (running-everywhere? id)
                                     (lab-task-standby (entry-of id))))))
    (let* ((e (entry-of id)) (coordinator (lab-task-coordinator e))
           (standby (lab-task-standby e)))
      (kill! coordinator)
      (kill! standby)
      (test-assert "task-wait says it failed, and why"
        (text-contains? (error-text (lambda () (task-wait id 30)))
                        "its coordinator and its standby both lost"))
      (test-assert "its component stops on its robot, as an orphan"
        (wait-until 10 (lambda () (any (lambda (r) (pair? (log-lines r "end" 'orphaned)))
                                       robots))))
      (test-assert "and nothing is held after the lease" (wait-until 6 all-free?))
      (restart! coordinator)
      (restart! standby))))

(test-group "a robot lost while the standby is in charge"
  (let ((id (running-detached 'moved 100)))
    (let ((old (coordinator-of id)))
      (kill! old)
      (test-assert "the standby takes over"
        (wait-until 10 (lambda () (let ((c (coordinator-of id))) (and c (not (eq? c old)))))))
      (let ((robot (cadr (status-state (car (task-status id))))))
        (kill! robot)
        (let ((results (task-wait id 30)))
          (test-assert "the component is reassigned, and completes elsewhere"
            (and (memq (car results) robots) (not (eq? (car results) robot))))
          (test "the lost robot is among its attempts" 'lost
            (cadr (assq robot (status-attempts (car (task-status id)))))))
        (restart! robot))
      (restart! old))))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
