;;; Address spaces on separate hosts: each robot's address space in a
;;; Linux network namespace of its own, on its own address, joined to this
;;; one by a veth link on a bridge.  A task is posed across them, by
;;; multicast delivery; one robot's link is cut mid-task, and its component
;;; moves to a robot on the other side; when the link returns, the stale
;;; component has stopped.  Needs root and iproute2; elsewhere it says
;;; "skipped: WHY" and tests/run counts it neither way.
;;;
;;; Everything it makes is named after its process id (two runs at once do
;;; not meet) and removed at the end, however the test ends; it sends
;;; traffic only to the addresses it made and to loopback.
(import (except (scheme base) lambda define) (scheme write) (scheme eval)
        (scheme process-context)
        (srfi 1) (srfi 18) (srfi 132) (chibi test)
        (only (chibi process) current-process-id system?)
        (murdoch) (murdoch remote) (murdoch command) (murdoch testing))

(define (can-run?)
  (cond ((not (equal? (command-output '("id" "-u")) "0")) "needs root")
        ((not (system? "sh" "-c" "command -v ip >/dev/null")) "needs iproute2 (ip)")
        ((not (system? "sh" "-c" "ip netns list >/dev/null 2>&1"))
         "ip netns does not work here")
        (else #t)))

(define why (can-run?))
(when (string? why)
  (display (string-append "skipped: " why)) (newline)
  (exit 0))

(define id (number->string (current-process-id)))
;; A /24 of its own, by process id: 10.S.77.0/24.
(define subnet (string-append "10." (number->string (+ 20 (modulo (current-process-id) 200))) ".77."))
(define (address i) (string-append subnet (number->string i)))
(define bridge (string-append "mdb" id))
(define robots '(near far spare))
(define (netns uid) (string-append "md" id "-" (symbol->string uid)))
(define (veth uid) (string-append "md" id (substring (symbol->string uid) 0 1)))
(define (peer uid) (string-append (veth uid) "p"))

(define (ip . args)
  (if (not (apply system? "ip" args))
      (error "ip failed" args)))

(define made '())                       ; what to remove, newest first
(define (made! what) (set! made (cons what made)))

(define (set-up!)
  (ip "link" "add" bridge "type" "bridge")
  (made! (list "link" "del" bridge))
  (ip "addr" "add" (string-append (address 1) "/24") "dev" bridge)
  (ip "link" "set" bridge "up")
  (for-each
   (lambda (uid i)
     (ip "netns" "add" (netns uid))
     (made! (list "netns" "del" (netns uid)))
     (ip "link" "add" (veth uid) "type" "veth" "peer" "name" (peer uid))
     (ip "link" "set" (peer uid) "netns" (netns uid))
     (ip "link" "set" (veth uid) "master" bridge "up")
     (ip "-n" (netns uid) "addr" "add" (string-append (address i) "/24") "dev" (peer uid))
     (ip "-n" (netns uid) "link" "set" (peer uid) "up")
     (ip "-n" (netns uid) "link" "set" "lo" "up")
     ;; Multicast leaves by the link, which a route for the group says.
     (ip "-n" (netns uid) "route" "add" "224.0.0.0/4" "dev" (peer uid)))
   robots (iota (length robots) 2)))

(define (tear-down!)
  (stop-all-processes!)
  (for-each (lambda (args) (apply system? "ip" args)) made)
  (set! made '()))

(define group (string-append "239.255." (number->string (modulo (current-process-id) 250)) ".9"))

(define lab-code "
(define spins 0)
(define stopped #f)
(define (spin-long)
  (dynamic-wind
   (lambda () #f)
   (lambda ()
     (let loop ((n 2000))
       (set! spins (+ spins 1))
       ;; Calls out to the poser, as a robot command would go to its robot.
       (remote-apply (uid->aspace 'tester) (lambda () #t))
       (thread-sleep! 0.05)
       (if (> n 0) (loop (- n 1)) (local-aspace-uid))))
   (lambda () (set! stopped #t))))
")

(define lab #f)

(define (start-robot! uid)
  (start-process! (list "ip" "netns" "exec" (netns uid)
                        (tool-path "bin/murdoch") "aspace" (test-lab-file lab)
                        (symbol->string uid))
                  (string-append (test-lab-directory lab) "/" (symbol->string uid) ".log")))

(define (spins-at uid)
  (remote-apply (uid->aspace uid) (eval '(lambda () spins) (lab-environment))))
(define (stopped-at? uid)
  (remote-apply (uid->aspace uid) (eval '(lambda () stopped) (lab-environment))))
(define (state-of t) (cadr (car (task-status t))))
(define (running-on t) (and (eq? (car (state-of t)) 'running) (cadr (state-of t))))

(test-begin "hosts in network namespaces")

(dynamic-wind
 (lambda () #f)
 (lambda ()
   (set-up!)
   (set! lab
         (make-test-lab
          `((code "code.scm") (heartbeat 0.3) (timeout 2)
            (delivery multicast ,group)
            (aspace tester (host ,(address 1)))
            (aspace near (host ,(address 2)) (position 100 0 0) (capabilities mobile) (load 0.5))
            (aspace far (host ,(address 3)) (position 3000 0 0) (capabilities mobile) (load 0.5))
            (aspace spare (host ,(address 4)) (position 6000 0 0) (capabilities mobile) (load 0.5)))
          `(("code.scm" . ,lab-code))))
   (for-each start-robot! robots)
   (join-lab (test-lab-file lab) 'tester)

   (test-group "every host answers, from its own address"
     (test "each robot, in its namespace" robots
       (map (lambda (uid)
              (wait-until 20 (lambda () (guard (e (#t #f))
                                          (remote-apply (uid->aspace uid) local-aspace-uid)))))
            robots))
     (test "delivery is multicast" 'multicast (delivery-mode))
     (test "one datagram reaches all four" '(far near spare tester)
       (wait-until 10 (lambda ()
                        (let ((acks (list-sort (lambda (a b) (string<? (symbol->string a)
                                                                        (symbol->string b)))
                                               (publish 'all (lambda () #t)))))
                          (and (= (length acks) 4) acks))))))

   (test-group "a link cut mid-task"
     (let ((t (start-task 'across 1 (list '((mobile) ()))
                          (list (location-metric-maker '(0 0 0 0)))
                          (list (eval 'spin-long (lab-environment))) '(1) '(#t))))
       (test "it runs on near" 'near
         (wait-until 15 (lambda () (and (eq? (running-on t) 'near)
                                        (> (spins-at 'near) 0)
                                        'near))))
       (ip "link" "set" (veth 'near) "down")
       (test "its component moves to a robot on the other side" #t
         (and (wait-until 15 (lambda () (memq (running-on t) '(far spare)))) #t))
       (test "the status says near was lost" 'lost
         (cadr (car (car (cddr (car (task-status t)))))))
       (ip "link" "set" (veth 'near) "up")
       (test "when the link returns, near's stale component has stopped" #t
         (wait-until 20 (lambda () (guard (e (#t #f)) (stopped-at? 'near)))))
       (let ((before (spins-at 'near)))
         (thread-sleep! 0.5)
         (test "and runs no more" before (spins-at 'near)))
       (cancel-task t)
       (test-assert "the task ends" (pair? (task-wait t 10))))))
 (lambda ()
   (tear-down!)
   (if lab (remove-test-lab! lab))))

(test "everything made is gone" '()
  (filter (lambda (name)
            (system? "sh" "-c" (string-append "ip netns list | grep -q '^" name "'")))
          (map netns robots)))
(test "the bridge too" #f
  (system? "sh" "-c" (string-append "ip link show " bridge " >/dev/null 2>&1")))

(test-end)
(test-exit)
