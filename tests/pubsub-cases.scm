;;; The publish/subscribe tests, for each delivery: the thesis's Figures
;;; 4.1-4.3, a race for one subject, leases, monitors and membership.
;;; Included by pubsub-test.scm (broadcast) and pubsub-multicast-test.scm,
;;; which define `delivery', the lab clauses that choose it.

(define lab-code "
(define *evaluated* 0)
(define (note!) (set! *evaluated* (+ 1 *evaluated*)) (local-aspace-uid))
(define *inside* 0)
(define *most-inside* 0)
(define *runs* 0)
(define (inside!)
  (set! *runs* (+ *runs* 1))
  (set! *inside* (+ *inside* 1))
  (set! *most-inside* (max *most-inside* *inside*))
  (thread-sleep! 0.001)
  (set! *inside* (- *inside* 1)))
;; Takes the wheel n times for task, holding each promise a moment before
;; committing it, so that two contenders overlap as much as they can.
(define (contend task n)
  (let loop ((i 0) (won 0))
    (if (= i n)
        won
        (let ((promises (request-exclusive '((wheel) ()) task inside!)))
          (thread-yield!)
          (for-each (lambda (p) ((cadr p) #t)) promises)
          (loop (+ i 1) (+ won (length promises)))))))
(define (reserve-and-stall)
  (request-exclusive '((wheel) ()) 'doomed inside!)
  (thread-sleep! 3600))
;; The askings of request-components, in the order they were asked.
(define *asked* '())
(define (note-asked! k) (set! *asked* (cons k *asked*)) k)
(define (asked-order) (let ((order (reverse *asked*))) (set! *asked* '()) order))
")


(define lab
  (make-test-lab
   `((code "code.scm") (lease 2) (monitor-period 1/4) ,@delivery
     (aspace tester)
     (aspace a (capabilities foo bar) (load 0.1))
     (aspace b (capabilities foo wheel) (load 0.9))
     (aspace c (capabilities foo bar) (load ((0 0.9) (1 0.1))))
     (aspace d))
   `(("code.scm" . ,lab-code))))


(define pids (map (lambda (uid) (cons uid (start-lab-aspace! lab uid))) '(a b c d)))
(join-lab (test-lab-file lab) 'tester)

(define (at uid proc . args) (apply remote-apply (uid->aspace uid) proc args))
(define (status uid topic) (at uid topic-status topic))
(define (evaluated uid) (at uid (eval '(lambda () *evaluated*) (lab-environment))))
(define (uid<? x y) (string<? (symbol->string x) (symbol->string y)))
(define (sorted-uids ls) (list-sort uid<? ls))
(define (by-uid answers) (list-sort (lambda (x y) (uid<? (car x) (car y))) answers))
(define (lab-proc name) (eval name (lab-environment)))

(test-begin (if (null? delivery) "pubsub" "pubsub over multicast"))

(test "the lab's delivery is in force" (if (null? delivery) 'broadcast 'multicast)
  (delivery-mode))

;; First, while no robot here has been freed since it joined: a robot
;; freed asks the posers whether tasks wait for it, and in a lab where
;; none has waited it refuses no request meanwhile (task/offers.scm).
(test-group "robots freed for the first time promise again at once"
  (test "a, b and c promise, are freed, and promise again" '(3 3 3)
    (map (lambda (i)
           (let ((promises (request-exclusive '((foo) ()) 'freed-first (lambda () #t))))
             (for-each (lambda (p) ((cadr p) #f)) promises)
             (length promises)))
         (iota 3))))

(test-group "subscribe and unsubscribe"
  (test "every address space has all and its uid" #t
    (every (lambda (u) (and (memq 'all (at u subscriptions))
                            (memq u (at u subscriptions)) #t))
           '(a b c d)))
  (test "subscribe is idempotent" 1
    (begin (subscribe 'extra) (subscribe 'extra)
           (count (lambda (t) (eq? t 'extra)) (subscriptions))))
  (test "unsubscribe is idempotent" #f
    (begin (unsubscribe 'extra) (unsubscribe 'extra)
           (memq 'extra (subscriptions))))
  (test "subscribe-remote" 'free
    (begin (subscribe-remote 'd '(spare parts))
           (if (null? (status 'd 'spare)) 'free 'held)))
  (test "unsubscribe-remote" #f
    (begin (unsubscribe-remote 'd 'spare) (status 'd 'spare))))

(test-group "Figure 4.1: publish"
  (test "every machine acknowledges" '(a b c d tester)
    (sorted-uids (publish '(foo bar) (lab-proc 'note!))))
  (test "A and C evaluate it, B does not" '(1 0 1)
    (begin
      (wait-until 5 (lambda () (= 1 (evaluated 'a) (evaluated 'c))))
      (map evaluated '(a b c)))))

(test-group "many threads publishing at once"
  ;; By multicast each publish is one datagram, numbered by its sender:
  ;; two threads taking one number would have the second dropped.
  (let* ((before (evaluated 'a))
         (publisher (lambda ()
                      (do ((k 0 (+ k 1))) ((= k 10))
                        (publish 'foo (lab-proc 'note!)))))
         (threads (map (lambda (i) (make-thread publisher)) (iota 8))))
    (for-each thread-start! threads)
    (for-each thread-join! threads)
    (test "each of 80 publishes ran on a" (+ before 80)
      (wait-until 10 (lambda () (let ((n (evaluated 'a)))
                                  (and (= n (+ before 80)) n)))))))

(test-group "Figure 4.2: request"
  (test "A and C answer with their uids" '((a a) (c c))
    (by-uid (request '(foo bar) (lambda () (local-aspace-uid)))))
  (test "a subject nobody has: no answers" '()
    (request 'nobody-has-this (lambda () 1)))
  (test "one subject, not a list" '((b 2))
    (request 'wheel (lambda () 2)))
  (test "point to point through the uid subject" '((c 9))
    (request 'c (lambda () 9))))

(test-group "a long request does not hold up the one behind it"
  ;; A and C run the long one in the thread that reads the lab's messages
  ;; to them; the quick one behind it gets a new reader.
  (let ((long (make-thread
               (lambda ()
                 (request '(foo bar) (lambda () (thread-sleep! 2) 'slow))))))
    (thread-start! long)
    (thread-sleep! 1/5)
    (test "the quick one is answered by A and C" '((a quick) (c quick))
      (parameterize ((remote-timeout 1))
        (by-uid (request '(foo bar) (lambda () 'quick)))))
    (test "and so is the long one" '((a slow) (c slow))
      (by-uid (thread-join! long)))))

(test-group "wrong arguments are refused at the call"
  (test "a procedure that is not one" "request: not a procedure"
    (error-text (lambda () (request 'all 5))))
  (test "a subject that is not a symbol" "publish: a subject is a symbol"
    (error-text (lambda () (publish '(foo "bar") (lambda () 1)))))
  (test "in request-exclusive's layout too" "request-exclusive: a subject is a symbol"
    (error-text (lambda () (request-exclusive '((wheel) ("foo")) 'task (lambda () 1)))))
  (test "subscribe" "subscribe: a subject is a symbol"
    (error-text (lambda () (subscribe "foo"))))
  (test "and nothing was reserved" '() (status 'b 'wheel)))

(test-group "an error in a message"
  ;; Each address space answers with the error at once, rather than
  ;; leaving its sender to time out.
  (test "is each address space's answer" '("car: not a pair ()")
    (delete-duplicates
     (map (lambda (r) (if (result-ok? r) 'no-error (result-value r)))
          (parameterize ((remote-timeout 2))
            (broadcast-apply (lambda () (car '())))))))
  (let* ((log (open-output-string))
         (answers (parameterize ((current-error-port log))
                    (request '(foo bar) (lambda () (car '()))))))
    (test "request leaves out the address spaces it raised in" '() answers)
    (test "and warns of each, naming it and the error"
        '("murdoch tester: warning: request on a failed: car: not a pair ()"
          "murdoch tester: warning: request on c failed: car: not a pair ()")
      (list-sort string<? (text-lines (get-output-string log)))))
  (test "and every address space serves on" '(a b c d tester)
    (sorted-uids (map car (request 'all (lambda () 1))))))

(test-group "Figure 4.3: request-exclusive and promises"
  (let ((promises (request-exclusive '((foo bar) ()) 'task1 (lambda () 'done))))
    (test "A and C reserve and promise" '(a c) (sorted-uids (map car promises)))
    (test "their subjects are held for task1" '(task1 task1 task1)
      (list (status 'a 'foo) (status 'a 'bar) (status 'c 'foo)))
    (test "S.in_use says why" '(a c)
      (sorted-uids (map car (request 'foo.in_use (lambda () #t)))))
    (test "request-status names the holder" '((a ((foo task1))))
      (filter (lambda (r) (eq? (car r) 'a)) (request-status 'foo)))
    (test "another task is refused meanwhile" '()
      (request-exclusive '((foo bar) ()) 'task2 (lambda () 'no)))
    (test "the same task is not" '(a b c)
      (let ((more (request-exclusive '((foo) ()) 'task1 (lambda () 'x))))
        (for-each (lambda (p) ((cadr p) #f)) more)
        (sorted-uids (map car more))))
    (test "still held by the first promises" 'task1 (status 'a 'foo))
    (let ((a (cadr (assq 'a promises)))
          (c (cadr (assq 'c promises))))
      (test "C's promise applied to #f frees C" '(#f ())
        (let* ((result (c #f))) (list result (status 'c 'foo))))
      (test "A's promise applied to #t runs the body there" 'done (a #t))
      (test "and frees A" '(() ())
        (list (status 'a 'foo) (status 'a 'bar)))
      (test "a promise is good once" #t
        (guard (e ((remote-error? e) #t)) (a #t) #f))))
  (test "the one-subject form" '(b)
    (let ((ps (request-exclusive 'wheel 'task3 (lambda () 1))))
      (for-each (lambda (p) ((cadr p) #f)) ps)
      (map car ps))))

(test-group "request-components takes the components in order"
  ;; note-asked! is the lab code's, found where the asking runs.
  (let ((asking (lambda (k) (lambda () (note-asked! k)))))
    (request-components 'in-order
                        (map (lambda (k)
                               (list 'non-exclusive '(() (foo)) (lambda () #t)
                                     (list (asking k))))
                             '(1 2 3)))
    (test "each address space asks the first component's first" '(1 2 3)
      (at 'a (lab-proc 'asked-order)))))

(test-group "a component not addressed here comes without its code"
  ;; only-here is the tester's own: it travels by name, and no other
  ;; address space has it (remote/served-call.scm, screen-calls!).
  (eval '(define (only-here) 'ran) (lab-environment))
  (let ((components (list (list 'exclusive '((wheel) ()) (lab-proc 'only-here) '())
                          (list 'non-exclusive '(() (bar)) (lab-proc 'only-here) '()))))
    (test "d, with neither subject, answers both without decoding" '(((#f d) ()) ((#f d) ()))
      (at 'd receive-components components 'screened 'tester))
    (test "b, with wheel, decodes the first, and cannot" 'raised
      (guard (e ((remote-error? e) 'raised))
        (at 'b receive-components components 'screened 'tester)))
    (test "a, with bar, decodes the second, and cannot" 'raised
      (guard (e ((remote-error? e) 'raised))
        (at 'a receive-components components 'screened 'tester)))))

(test-group "request-non-exclusive"
  (let* ((r1 (request-non-exclusive 'foo 'reader1 (lambda () 'read1)))
         (r2 (request-non-exclusive 'foo 'reader2 (lambda () 'read2))))
    (test "readers share" '(3 3) (list (length r1) (length r2)))
    (test "the status says shared" 'shared (status 'b 'foo))
    (test "an exclusive taker is refused while they read" '()
      (request-exclusive '((foo) ()) 'writer (lambda () 'w)))
    (test "readers finish" '(read1 read2)
      (list ((cadr (assq 'b r1)) #t) ((cadr (assq 'b r2)) #t)))
    (for-each (lambda (p) (if (not (eq? (car p) 'b)) ((cadr p) #f)))
              (append r1 r2))
    (test "then the writer gets it" '(a b c)
      (let ((ps (request-exclusive '((foo) ()) 'writer (lambda () 'w))))
        (for-each (lambda (p) ((cadr p) #f)) ps)
        (sorted-uids (map car ps))))))

(test-group "wildcards"
  (test "* matches one level" '(b)
    (begin (subscribe-remote 'b 'arm.left)
           (map car (request 'arm.* (lambda () #t)))))
  (test "> matches the rest" '(b)
    (begin (subscribe-remote 'b 'arm.left.gripper)
           (map car (request '(arm.> wheel) (lambda () #t)))))
  (test "but not nothing" '()
    (request 'wheel.> (lambda () #t)))
  (test "a subject subscribed with its wildcard matches itself" '(b c)
    (begin (subscribe-remote 'c 'arm.*)
           (let ((uids (sorted-uids (map car (request 'arm.* (lambda () #t))))))
             (unsubscribe-remote 'c 'arm.*)
             uids))))

(test-group "a race for one subject"
  ;; a and c each take b's wheel 200 times, at once.
  (let ((ta (make-thread (lambda () (at 'a (lab-proc 'contend) 'task-a 200))))
        (tc (make-thread (lambda () (at 'c (lab-proc 'contend) 'task-c 200)))))
    (parameterize ((remote-timeout 120))
      (thread-start! ta) (thread-start! tc)
      (let ((won-a (thread-join! ta))
            (won-c (thread-join! tc)))
        (test "both contenders won some of the time" #t
          (and (> won-a 0) (> won-c 0)))
        (test "never two promises live at once" 1
          (at 'b (eval '(lambda () *most-inside*) (lab-environment))))
        (test "every promise won ran once" (+ won-a won-c)
          (at 'b (eval '(lambda () *runs*) (lab-environment))))
        (test "and the wheel is free at the end" '() (status 'b 'wheel))))))

(test-group "leases"
  (remote-run! (uid->aspace 'd) (lab-proc 'reserve-and-stall))
  (test "d holds the wheel" 'doomed
    (wait-until 5 (lambda () (let ((s (status 'b 'wheel))) (and (symbol? s) s)))))
  (kill-process! (cdr (assq 'd pids)))
  (test "d is killed before applying its promise; the lease frees it" '()
    (wait-until 10 (lambda () (let ((s (status 'b 'wheel))) (and (null? s) s))))))

(test-group "monitors"
  (test "a light load subscribes idle, a heavy one does not" '(#t #f)
    (list (and (memq 'idle (at 'a subscriptions)) #t)
          (and (memq 'idle (at 'b subscriptions)) #t)))
  (test "a load that falls brings idle" #t
    (wait-until 10 (lambda () (and (memq 'idle (at 'c subscriptions)) #t))))
  (test "get-system-load answers a string, as the thesis's" "0.1"
    (at 'a get-system-load))
  (test "a load that changed is answered as it is now" "0.1"
    (at 'c get-system-load))
  (test "a caller that changes the string it got changes no later answer" "0.1"
    (at 'a (lambda ()
             (string-set! (get-system-load) 0 #\9)
             (get-system-load))))
  (test "without a load clause, the load is /proc/loadavg's" #t
    (let ((load (string->number (get-system-load))))  ; the tester has none
      (and (real? load) (>= load 0)))))

(test-group "membership"
  (test "a peer that is killed is not counted" '(b c tester)
    (begin (kill-process! (cdr (assq 'a pids)))
           (sorted-uids (publish 'all (lambda () #t)))))
  (set-cdr! (assq 'a pids) (start-lab-aspace! lab 'a))
  (test "restarted, it is counted again within seconds" '(a b c tester)
    (wait-until 10 (lambda ()
                     (let ((acks (sorted-uids (publish 'all (lambda () #t)))))
                       (and (equal? acks '(a b c tester)) acks))))))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
