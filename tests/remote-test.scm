;;; The remote layer between real address spaces on loopback.
(import (except (scheme base) lambda define) (scheme write) (scheme file)
        (scheme eval) (scheme read)
        (srfi 18) (chibi test) (chibi net)
        (only (chibi filesystem) open-input-file-descriptor
              open-output-file-descriptor)
        (murdoch) (murdoch remote) (only (murdoch remote aspace) lab-environment make-aspace)
        (murdoch cli command) (murdoch lab)
        (murdoch wire netstring) (murdoch wire hmac) (murdoch wire connect)
        (only (murdoch wire) error-message)
        (murdoch testing harness)
        (murdoch testing raw)
        (only (murdoch sys wait) make-mailbox mailbox-put! mailbox-take)
        (only (murdoch sys scheduler) monotonic-seconds))

(define shared-code "
(define *counter* 0)
(define (bump!) (set! *counter* (+ *counter* 1)) *counter*)
(define (slow seconds) (thread-sleep! seconds) 'done)
(define *last-abandoned* #f)
")

(define lab
  (make-test-lab '((code "shared.scm") (frame-timeout 1)
                   (aspace tester) (aspace troy) (aspace ghost)
                   (aspace praline))
                 `(("shared.scm" . ,shared-code))))


;; The lab's code, as this address space loaded it.
(define (lab-procedure name) (eval name (lab-environment)))
(define bump! #f)
(define slow #f)

(define troy-pid (start-lab-aspace! lab 'troy))
(define praline-pid (start-lab-aspace! lab 'praline))
(join-lab (test-lab-file lab) 'tester)
(set! bump! (lab-procedure 'bump!))
(set! slow (lab-procedure 'slow))

(define (troy) (uid->aspace 'troy))

(test-begin "remote")

(test-group "remote-apply"
  (test 3 (remote-apply (troy) (lambda () (+ 1 2))))
  (test "arguments travel" '(2 4 6)
    (remote-apply (troy) (lambda (xs k) (map (lambda (x) (* x k)) xs))
                  '(1 2 3) 2))
  (test "data of every kind comes back"
      '(1 2.5 1/3 "é" #\x sym #u8(1 2) #(1 #(2)) () #t #f)
    (remote-apply (troy) (lambda ()
                           (list 1 2.5 1/3 "é" #\x 'sym (bytevector 1 2)
                                 (vector 1 (vector 2)) '() #t #f))))
  (test "a closure over data, as the thesis sends them" '(300 200 0)
    (let ((coords '(300 200 0)))
      (remote-apply (troy) (lambda () coords))))
  (test "a closure made there comes back and runs here" 42
    ((remote-apply (troy) (lambda () (let ((n 41)) (lambda () (+ n 1)))))))
  (test "runs in the target, not here" 'troy
    (remote-apply (troy) (lambda () (local-aspace-uid))))
  (test "a local target runs in-process" 'tester
    (remote-apply (local-aspace) (lambda () (local-aspace-uid)))))

(test-group "errors"
  (test "an error there names the target, procedure and message"
      '(troy (lambda () (car '())) "car: not a pair ()")
    (guard (e ((remote-error? e) (error-object-irritants e)))
      (remote-apply (troy) (lambda () (car '())))))
  (test "a result that cannot travel back is an error, saying why"
      "cannot send the result: it is a mutex"
    (error-text (lambda () (remote-apply (troy) (lambda () (make-mutex))))))
  (test "and the address space answers the next call" 3
    (remote-apply (troy) (lambda () (+ 1 2))))
  (test "an unsendable value is refused here, naming the variable"
      "cannot send variable port of (lambda () port): it is an output port"
    (let ((port (current-output-port)))
      (error-text (lambda () (remote-apply (troy) (lambda () port))))))
  (test "a uid where an address space belongs is refused, saying what to do"
      "remote-apply: not an address space; (uid->aspace UID) gives one"
    (error-text (lambda () (remote-apply 'troy (lambda () 1)))))
  (test "by remote-run! and the -all forms too"
      '("remote-run!: not an address space; (uid->aspace UID) gives one"
        "remote-apply-all: not an address space; (uid->aspace UID) gives one")
    (list (error-text (lambda () (remote-run! 'troy (lambda () 1))))
          (error-text (lambda () (remote-apply-all (list (troy) 'troy) (lambda () 1))))))
  (test "a timeout, set per call"
      "no answer within 1/2 s"
    (parameterize ((remote-timeout 1/2))
      (error-text (lambda () (remote-apply (troy) slow 3)))))
  (test "the connection still works after a timeout" 3
    (remote-apply (troy) (lambda () 3)))
  (test "as one line, a remote error says its own message: the uid is beside it"
      '("car: not a pair ()" "no answer within 1/2 s")
    (map (lambda (thunk) (guard (e (#t (error-message e))) (thunk)))
         (list (lambda () (remote-apply (troy) (lambda () (car '()))))
               (lambda () (parameterize ((remote-timeout 1/2))
                            (remote-apply (troy) slow 3))))))
  (test "an error from a third address space names it, the caller's answer"
      "praline: car: not a pair ()"
    (error-text (lambda ()
                  (remote-apply (troy)
                                (lambda ()
                                  (remote-apply (uid->aspace 'praline)
                                                (lambda () (car '()))))))))
  (test "and so does remote-apply-all's outcome of each that failed"
      '((troy #f "car: not a pair ()") (praline #t 2))
    (remote-apply-all (list (troy) (uid->aspace 'praline))
                      (lambda () (if (eq? (local-aspace-uid) 'troy) (car '()) 2)))))

(test-group "each way a call fails has a predicate of its own"
  (define (failure thunk) (guard (e (#t e)) (thunk)))
  (test "no answer in time" '(#t #t)
    (let ((e (failure (lambda () (parameterize ((remote-timeout 1/2))
                                   (remote-apply (troy) slow 3))))))
      (list (remote-error? e) (remote-timeout-error? e))))
  (test "raised there" '(#t #t)
    (let ((e (failure (lambda () (remote-apply (troy) (lambda () (car '())))))))
      (list (remote-error? e) (remote-raised-error? e))))
  (test "nobody listening" '(#t #t)
    (let ((e (failure (lambda () (remote-apply (uid->aspace 'ghost) (lambda () 1))))))
      (list (remote-error? e) (remote-unreachable-error? e))))
  (test "a listener that answers the hello with something else" '(#t #t)
    (let* ((listener (listen-on-free-port))
           (answerer (make-thread
                      (lambda ()
                        (let* ((addr (get-address-info "127.0.0.1" (cdr listener)))
                               (fd (accept (car listener) (address-info-address addr)
                                           (address-info-address-length addr)))
                               (out (open-output-file-descriptor fd)))
                          (write-string "5:hello," out)
                          (flush-output-port out)
                          (thread-sleep! 1)
                          (close-port out))))))
      (thread-start! answerer)
      (let ((e (failure (lambda ()
                          (parameterize ((remote-timeout 2))
                            (remote-apply (make-aspace 'liar "127.0.0.1" (cdr listener))
                                          (lambda () 1)))))))
        (thread-join! answerer)
        (close-port (open-input-file-descriptor (car listener)))
        (list (remote-error? e) (remote-protocol-error? e))))))

(test-group "a long apply does not hold up the calls behind it"
  ;; The connection's reader runs an apply itself; one that runs long has
  ;; the connection handed to a new reader, so that the quick call behind
  ;; it is answered well before the slow one ends.
  (let ((long (make-thread (lambda () (remote-apply (troy) slow 3))))
        (failing (make-thread
                  (lambda ()
                    (error-text
                     (lambda ()
                       (remote-apply (troy) (lambda ()
                                              (thread-sleep! 2)
                                              (car '())))))))))
    (thread-start! long)
    (thread-start! failing)
    (thread-sleep! 1/5)
    (test "a quick call behind it is answered" 'quick
      (parameterize ((remote-timeout 1))
        (remote-apply (troy) (lambda () 'quick))))
    (test "the long one is answered by its own thread" 'done
      (thread-join! long))
    (test "one that fails meanwhile is answered with its error"
        "car: not a pair ()"
      (thread-join! failing))
    (test "the connection serves on" 3
      (remote-apply (troy) (lambda () 3)))))

(test-group "remote-run!"
  (test "acknowledged" #t (remote-run! (troy) bump!))
  (test "applied there in a thread of its own" 1
    (wait-until 5 (lambda () (let ((n (var-ref 'troy *counter*)))
                               (and (= n 1) n)))))
  (test "var-set!" 10 (begin (var-set! 'troy *counter* 10)
                             (var-ref 'troy *counter*))))

(test-group "encap"
  (let ((p (remote-apply (troy)
                         (lambda ()
                           (let ((n 0))
                             (encap (lambda () (set! n (+ n 1))
                                            (list (local-aspace-uid) n))))))))
    (test "a proxy runs where it was made" '(troy 1) (p))
    (test "and keeps its state there" '(troy 2) (p))
    (test "sent back and forth, it stays the same proxy" #t
      (eq? p (remote-apply (troy) (lambda (q) q) p)))
    (test "applied from a third address space, it still runs there"
        '(troy 3)
      (remote-apply (uid->aspace 'praline) (lambda (q) (q)) p))))

(test-group "dead and returning peers"
  (kill-process! praline-pid)
  (test "a dead target raises instead of hanging" #t
    (remote-error? (guard (e (#t e))
                     (remote-apply (uid->aspace 'praline) (lambda () 1)))))
  (set! praline-pid (start-lab-aspace! lab 'praline))
  (test "a restarted target is reached again" 7
    (remote-apply (uid->aspace 'praline) (lambda () 7)))
  ;; As when a guest left and the next one listens on its port.
  (test "another address space on a gone one's port does not answer for it"
      "found troy at its address"
    (error-text (lambda ()
                  (remote-apply (make-aspace 'gone "127.0.0.1"
                                             (aspace-port (troy)))
                                (lambda () (local-aspace-uid)))))))

(define ghost-address
  (get-address-info "127.0.0.1" (aspace-port (uid->aspace 'ghost))))

(test-group "an address space that takes the connection and never greets"
  ;; A listener that never accepts: the kernel completes the connect, and
  ;; the hello waits in its queue unread.
  (let ((listener (make-listener-socket ghost-address 5)))
    (test "raises within the timeout, saying so" "no welcome"
      (parameterize ((remote-timeout 1))
        (error-text (lambda ()
                      (remote-apply (uid->aspace 'ghost) (lambda () 1))))))
    (close-port (open-input-file-descriptor listener))))

(test-group "an address space that does not answer the connect"
  ;; A listener that never accepts, its queue filled (by the filler, or
  ;; by this address space's prober, which looks for ghost every second):
  ;; the next connect hangs, as for a robot that was switched off.
  (let* ((listener (make-listener-socket ghost-address 0))
         (filler (open-connection "127.0.0.1" (aspace-port (uid->aspace 'ghost))
                                  1)))
    (test "raises within the timeout, saying so"
        (string-append "cannot connect to 127.0.0.1:"
                       (number->string (aspace-port (uid->aspace 'ghost)))
                       ": no connection within 1 s")
      (parameterize ((remote-timeout 1))
        (error-text (lambda ()
                      (remote-apply (uid->aspace 'ghost) (lambda () 1))))))
    (test "and another address space answers meanwhile" 2
      (remote-apply (uid->aspace 'troy) (lambda () 2)))
    ;; Closed only here: collected earlier, the filler would free the queue.
    (if (pair? filler) (for-each close-port filler))
    (close-port (open-input-file-descriptor listener))))

(test-group "the sandbox"
  (let ((victim (string-append (test-lab-directory lab) "/victim")))
    (call-with-output-file victim (lambda (out) (write-string "keep" out)))
    (test "no delete-file there" "undefined variable delete-file"
      (error-text (lambda ()
                    (remote-apply (troy) (lambda () (delete-file victim))))))
    (test "the file is still there" #t (file-exists? victim))
    (test "no open-output-file there" "undefined variable open-output-file"
      (error-text (lambda ()
                    (remote-apply (troy)
                                  (lambda () (open-output-file
                                              (string-append victim "2")))))))
    (test "no file was made" #f (file-exists? (string-append victim "2")))
    (test "no exit there" "undefined variable exit"
      (error-text (lambda () (remote-apply (troy) (lambda () (exit 1))))))
    (test "no eval of another environment" "undefined variable eval"
      (error-text (lambda ()
                    (remote-apply (troy) (lambda () (eval '(exit 1) #f))))))))

;;; Raw connections, for what a well-behaved peer never sends
;;; (lib/murdoch/testing/raw.scm)

(define key (lab-key (read-lab (test-lab-file lab))))
(define (troy-raw-connect) (raw-connect (aspace-port (troy))))
(define (welcomed-troy nonce) (welcomed-raw-connect key (aspace-port (troy)) nonce))

(test-group "bad frames close only their own connection"
  (let ((bystander (troy-raw-connect)))
    (raw-send! bystander (hello-frame key "n1"))
    (for-each
     (lambda (name bytes)
       (let ((conn (troy-raw-connect)))
         (raw-send! conn bytes)
         (test name #t (raw-closed? conn))))
     '("garbage" "over-long length" "a frame that stalls half-way"
       "no comma" "no key: a wrong MAC")
     (list (string->utf8 "GET / HTTP/1.0\r\n\r\n")
           (string->utf8 "99999999999:")
           (string->utf8 "100:abc")
           (string->utf8 "3:abc;")
           (framed (make-string 64 #\0) (hello-text "n2"))))
    (let ((conn (troy-raw-connect)))
      (raw-send! conn (string->utf8 "100:abc"))
      (close-output-port (cdr conn))  ; the peer goes away mid-frame
      (test "a frame cut short" #t (raw-closed? conn)))
    (test "the bystander connection is still open, and answers" #t
      (let ((w (read-netstring (car bystander) 100000)))
        (bytevector? w)))
    (test "the address space still answers calls" 5
      (remote-apply (troy) (lambda () 5)))))

(test-group "a frame that arrives in pieces"
  ;; The reader takes a frame at once when its port's buffer holds all of
  ;; it; this one arrives in three writes, cut in its length and payload.
  (let* ((conn (troy-raw-connect))
         (bytes (hello-frame key "n4"))
         (n (bytevector-length bytes)))
    (raw-send! conn (bytevector-copy bytes 0 1))
    (thread-sleep! 0.05)
    (raw-send! conn (bytevector-copy bytes 1 (- n 10)))
    (thread-sleep! 0.05)
    (raw-send! conn (bytevector-copy bytes (- n 10) n))
    (test "is read whole, and answered with a welcome" 'welcome
      (car (raw-answer conn)))))

(test-group "nothing is evaluated without the key"
  (let ((before (var-ref 'troy *counter*))
        (conn (troy-raw-connect))
        (call-text (text-of '(run 1 #(murdoch:global bump!) ()))))
    (raw-send! conn (hello-frame key "n3"))
    (let ((welcome (utf8->string (read-netstring (car conn) 100000))))
      ;; A call MAC'd with a made-up key is refused and closes the connection.
      (raw-send! conn (framed (hmac-sha256 (string->utf8 "not the key")
                                           (string->utf8 call-text))
                              call-text))
      (test "the connection is closed" #t (raw-closed? conn))
      (test "and bump! never ran" before (var-ref 'troy *counter*)))))

(test-group "a recorded frame cannot be replayed"
  (let ((before (var-ref 'troy *counter*)))
    ;; First a genuine exchange, recorded.
    (let* ((welcomed (welcomed-troy "n4"))
           (conn (car welcomed))
           (call (counted key (cdr welcomed) 1 '(run 1 #(murdoch:global bump!) ()))))
      (raw-send! conn call)
      (test "the genuine call runs" (+ before 1)
        (wait-until 5 (lambda () (let ((n (var-ref 'troy *counter*)))
                                   (and (= n (+ before 1)) n)))))
      (test "replayed on the same connection, it is refused" #t
        (begin (read-netstring (car conn) 100000)   ; the ack
               (raw-send! conn call)
               (raw-closed? conn)))
      (let ((again (car (welcomed-troy "n4"))))
        (raw-send! again call)
        (test "replayed on a new connection, it is refused" #t (raw-closed? again)))
      (test "bump! ran once only" (+ before 1) (var-ref 'troy *counter*)))))

(test-group "a caller that gives up says so"
  (let* ((welcomed (welcomed-troy "n5"))
         (conn (car welcomed))
         (before (var-ref 'troy *counter*)))
    (raw-send! conn (counted key (cdr welcomed) 1 '(abandon 999)))
    (raw-send! conn (counted key (cdr welcomed) 2 '(run 1 #(murdoch:global bump!) ())))
    (test "an abandon for no running call is let be, and calls go on"
        (+ before 1)
      (wait-until 5 (lambda () (let ((n (var-ref 'troy *counter*)))
                                 (and (= n (+ before 1)) n)))))
    (read-netstring (car conn) 100000)         ; the ack
    (raw-send! conn (counted key (cdr welcomed) 3 '(abandon "1")))
    (test "a malformed abandon closes the connection" #t (raw-closed? conn)))
  (test "an apply that takes too long is stopped at its next remote call"
      "remote-apply: stopped, its caller gave up"
    (begin
      (guard (e (#t #f))
        (parameterize ((remote-timeout 0.5))
          (remote-apply (troy)
                        (lambda ()
                          (thread-sleep! 3) ; the abandon comes meanwhile
                          (set! *last-abandoned*
                                (guard (e (#t (error-object-message e)))
                                  (remote-apply (uid->aspace 'tester)
                                                (lambda () 'too-late))))))))
      (wait-until 10 (lambda () (var-ref 'troy *last-abandoned*))))))

;; A callee played by hand, as uid, at the lab's port base plus offset,
;; where no address space is (so that no prober calls it): it welcomes
;; one caller, reads its call, hands (answer! conn caller-nonce id) the
;; rest, and closes.
(define (hand-address offset)
  (get-address-info "127.0.0.1" (+ (test-lab-port-base lab) offset)))

(define (hand-played-callee uid offset answer!)
  (let* ((address (hand-address offset))
         (listener (make-listener-socket address 5)))
    (thread-start!
     (make-thread
      (lambda ()
        (let* ((fd (accept listener (address-info-address address)
                           (address-info-address-length address)))
               (conn (cons (open-input-file-descriptor fd #t)
                           (open-output-file-descriptor fd #t)))
               (caller-nonce (list-ref (raw-answer conn) 4)))
          (close-port (open-input-file-descriptor listener))
          (raw-send! conn (counted key caller-nonce 0 `(welcome ,uid "h1")))
          (answer! conn caller-nonce (cadr (raw-answer conn)))
          (raw-close! conn)))))))

(define (call-hand uid offset)
  (thread-start!
   (make-thread
    (lambda ()
      (parameterize ((remote-timeout 10))
        (error-text
         (lambda ()
           (remote-apply (make-aspace uid "127.0.0.1"
                                      (+ (test-lab-port-base lab) offset))
                         (lambda () 1)))))))))

(test-group "one poller reads every connection"
  ;; The answer comes in two writes; between them, another address space
  ;; is called and answers: the half frame holds up no other connection.
  (let* ((half-sent (make-mailbox))
         (go-on (make-mailbox))
         (hand (hand-played-callee
               'hand 50
                 (lambda (conn nonce id)
                   (let* ((bytes (counted key nonce 1 `(error ,id "in pieces")))
                          (n (bytevector-length bytes)))
                     (raw-send! conn (bytevector-copy bytes 0 (- n 7)))
                     (mailbox-put! half-sent #t)
                     (mailbox-take go-on (+ (monotonic-seconds) 10) (lambda () #f))
                     (raw-send! conn (bytevector-copy bytes (- n 7) n))))))
         (caller (call-hand 'hand 50)))
    (mailbox-take half-sent (+ (monotonic-seconds) 10) (lambda () #f))
    (test "another address space answers while a frame is half read" 5
      (remote-apply (troy) (lambda () 5)))
    (mailbox-put! go-on #t)
    (test "and the frame, once whole, answers its call" "in pieces"
      (thread-join! caller))
    (thread-join! hand))
  ;; A frame that is not a netstring: its connection closes, its call
  ;; hears so, and the others carry on.
  (let* ((hand (hand-played-callee
               'breaker 51
                 (lambda (conn nonce id)
                   (raw-send! conn (string->utf8 "12x:not a netstring,")))))
         (caller (call-hand 'breaker 51)))
    (test "a callee that breaks the wire fails only its own calls"
        "connection lost"
      (thread-join! caller))
    (test "and the others carry on" 6
      (remote-apply (troy) (lambda () 6)))
    (thread-join! hand)))

(test-end)
(stop-all-processes!)
(remove-test-lab! lab)
(test-exit)
