;;;; Where a message's CPU goes, stage by stage, beside the least the same
;;;; stage costs a bare Chibi process: issue 21's breakdown.
;;
;; Usage: tools/chibi bench/stages.scm
;;
;; The message a request to all sends each address space,
;; (receive-request 'all UID (lambda () #t) '()), taken apart: each stage
;; of the receiver and of the sender runs alone in a loop, here, with warm
;; caches, on the very message, and so does the least a bare Chibi process
;; does for the same: read a netstring, check its MAC, read the datum,
;; pick it apart, find the procedure, apply it, write the answer.  Then
;; two live processes: an address space's whole CPU per such call, and a
;; bare Chibi echo server's per message (the floor of chibi-pingpong-rtt
;; and of the fan-out), each from the process's own CPU clock, and the
;; caller's of each; what the stages leave of the whole is the wait and
;; wake, the thread's scheduling, the bookkeeping and the collector, with
;; caches that other processes have emptied.
;;
;; Three stages are work that a bare echo does not do at all: decoding a
;; procedure sent as its source, running it with ports and parameters of
;; its own, and encoding one.  For these a second floor does the same work
;; the least way bare Chibi can, without Murdoch's checks: a procedure
;; found by name in a table, a closure's maker found by its source in a
;; table and applied, the list copied by map; the subscription found by
;; memq and the user's procedure applied under a parameterize of the
;; thirteen parameters the sandbox binds for each call; a name, or a
;; source, found by the procedure in a table.  Prints
;;   stage: SIDE NAME MURDOCH-US BARE-US RATIO [SAME-WORK-US RATIO]
;; for each stage, in microseconds of CPU per message.

(import (except (scheme base) lambda define) (scheme write) (scheme time)
        (scheme file) (scheme process-context) (scheme eval)
        (srfi 1) (srfi 18) (srfi 69) (srfi 132)
        (chibi net) (chibi process) (chibi filesystem)
        (only (chibi) read) (rename (only (chibi) equal?) (equal? chibi-equal?))
        (murdoch) (murdoch cli command) (murdoch testing harness)
        (murdoch wire netstring) (murdoch wire hmac) (murdoch wire frame)
        (murdoch code sendable) (murdoch remote aspace) (murdoch code sandbox)
        (murdoch lab) (murdoch sys scheduler)
        (only (murdoch remote call) encode-arguments)
        (bench echo) (bench clock))

(define lab (make-test-lab '((aspace bencher) (aspace troy))))
(define key (lab-key (read-lab (test-lab-file lab))))
(define troy-pid
  (start-process! (list (tool-path "bin/murdoch") "aspace" (test-lab-file lab) "troy")
                  (string-append (test-lab-directory lab) "/troy.log")))
(wait-for-port (+ 1 (test-lab-port-base lab)) 20)
(join-lab (test-lab-file lab) 'bencher)

;;; Clocks

(define rounds 7)
(define loops 2000)

;; The median over rounds of the CPU per run of thunk, in microseconds;
;; (prepare) runs untimed before each round, for what thunk uses up.
(define (per-run thunk . prepare)
  (define (one-round)
    (if (pair? prepare) ((car prepare)))
    (let ((t0 (own-cpu-us)))
      (do ((i 0 (+ i 1))) ((= i loops)) (thunk))
      (/ (- (own-cpu-us) t0) loops)))
  (one-round)
  (let ((times (list-tabulate rounds (lambda (i) (one-round)))))
    (list-ref (list-sort < times) (quotient rounds 2))))

(define (report side name murdoch bare . same-work)
  (define (ratio floor) (if (> floor 0.05) (round1 (/ murdoch floor)) "-"))
  (for-each display (list "stage: " side " " name " " (round1 murdoch) " "
                          (round1 bare) " " (ratio bare)))
  (if (pair? same-work)
      (for-each display (list " " (round1 (car same-work)) " "
                              (ratio (car same-work)))))
  (newline))

(define (round1 x) (/ (round (* 10 x)) 10.))

;;; The message

(define user (lambda () #t))
(define args (list 'all 'bencher user '()))
(define env (lab-environment))
(define proc-code (encode receive-request env "the procedure"))
(define args-code (encode-arguments args))
(define call-message (make-message 'apply 7 proc-code args-code))
(define result (receive-request 'all 'bencher user '()))
(define answer-message (make-message 'value 7 result))
(define text-port (open-output-string))
(define (text-of message)
  (let ((t (frame-text text-port message))) (string-copy t)))
(define call-text (text-of call-message))
(define nonce "0123456789abcdef")

;; The bytes of a netstring on the wire, and its payload.
(define (signed text) (hmac-sha256-sign key text (list nonce ":" 1 ":")))
(define call-payload (string->utf8 (signed call-text)))

;; A connected pair of sockets in this process: frames are written to one
;; end and read at the other.
(define (socket-pair)
  (let* ((listener+port (listen-on-free-port))
         (addr (get-address-info "127.0.0.1" (cdr listener+port)))
         (io (open-net-io "127.0.0.1" (cdr listener+port)))
         (fd (accept (car listener+port) (address-info-address addr)
                     (address-info-address-length addr))))
    (list (open-input-file-descriptor fd) (car (cddr io)))))

(define pair (socket-pair))
(define in (car pair))
(define out (cadr pair))

;; loops frames written ahead, for a round of reads.
(define (fill! payload)
  (lambda ()
    (do ((i 0 (+ i 1))) ((= i loops)) (write-netstring payload out))
    (flush-output-port out)))

;;; The stages, Murdoch's way and the bare way

;; The least way to find a procedure: by a number, in a table.
(define decode-cache (make-hash-table eqv?))
(hash-table-set! decode-cache 1 (lambda () user))

;; The same work as decode, sandbox and encode, the least way bare Chibi
;; can (see the header).  A closure's maker is made by the plain lambda,
;; as bare Chibi would, and its table compares with Chibi's C equal?.
(define bare-globals (make-hash-table eq?))      ; name -> procedure
(hash-table-set! bare-globals 'receive-request receive-request)
(define bare-makers (make-hash-table chibi-equal?)) ; source -> maker
(hash-table-set! bare-makers '(lambda () #t)
                 (eval '(lambda () (lambda () #t))
                       (environment '(scheme base))))
(define bare-names (make-hash-table eq?))        ; procedure -> encoding
(hash-table-set! bare-names receive-request '#(murdoch:global receive-request))
(hash-table-set! bare-names user (vector 'murdoch:closure '(lambda () #t) '()))

(define (bare-decode x)
  (cond ((pair? x) (map bare-decode x))
        ((not (vector? x)) x)
        ((eq? (vector-ref x 0) 'murdoch:global)
         (hash-table-ref/default bare-globals (vector-ref x 1) #f))
        (else ((hash-table-ref/default bare-makers (vector-ref x 1) #f)))))

(define bare-subscriptions '(all bencher))
(define bare-ports (list (current-input-port) (current-output-port)
                         (current-error-port)))

(define coordinator (make-parameter #f))  ; team.scm keeps its own

;; A call's own binding of each parameter that the sandbox binds: the
;; three ports and Murdoch's ten (sandbox-parameter!).
(define (bare-receive topic uid proc args)
  (parameterize ((current-input-port (car bare-ports))
                 (current-output-port (cadr bare-ports))
                 (current-error-port (car (cddr bare-ports)))
                 (remote-timeout (remote-timeout))
                 (pose-task-progress (pose-task-progress))
                 (current-team (current-team))
                 (task-timeout (task-timeout))
                 (coordinator (coordinator))
                 (pose-task-assignment (pose-task-assignment))
                 (pose-task-priority (pose-task-priority))
                 (pose-task-retries (pose-task-retries))
                 (pose-task-backoff (pose-task-backoff))
                 (pose-task-excluded (pose-task-excluded)))
    (if (memq topic bare-subscriptions)
        (list #t 'troy (apply proc args))
        (list #f 'troy))))

(define (bare-encode x)
  (cond ((pair? x) (map bare-encode x))
        ((procedure? x) (hash-table-ref/default bare-names x #f))
        (else x)))

(define (stages side message text payload user)
  (define parsed (parse-message text))
  (report side "read"
          (per-run (lambda () (peek-u8 in) (monotonic-seconds)
                     (read-netstring in 1048576))
                   (fill! payload))
          (per-run (lambda () (read-netstring in 1048576)) (fill! payload)))
  (let ((n (bytevector-length payload)))
    (report side "MAC"
            (per-run (lambda ()
                       (hmac-sha256-open key payload n (list nonce ":" 1 ":"))))
            (per-run (lambda ()
                       (hmac-sha256-open key payload n (list nonce ":" 1 ":"))))))
  (report side "parse"
          (per-run (lambda () (parse-message text)))
          (per-run (lambda () (read (open-input-string text)))))
  (report side "dispatch"
          (per-run (lambda () (check-message parsed '(run apply answer abandon
                                                         ack value error)
                                             "a message")))
          (per-run (lambda () (case (car parsed) ((apply value) (cadr parsed))))))
  (user parsed))

(define (receiver-stages)
  (stages "receiver" call-message call-text call-payload
          (lambda (parsed)
            (report "receiver" "decode"
                    (per-run (lambda () (decode-value (list-ref parsed 2))
                               (decode-value (list-ref parsed 3))))
                    (per-run (lambda ()
                               ((hash-table-ref/default decode-cache 1 #f))))
                    (per-run (lambda () (bare-decode (list-ref parsed 2))
                               (bare-decode (list-ref parsed 3)))))
            (report "receiver" "subject match, sandbox, user procedure"
                    (per-run (lambda () (call-in-sandbox receive-request args)))
                    (per-run (lambda () (apply user '())))
                    (per-run (lambda () (apply bare-receive args))))
            (report "receiver" "encode"
                    (per-run (lambda () (encode result env "the result")))
                    0)
            (write-stages "receiver" answer-message))))

(define (sender-stages)
  (report "sender" "encode"
          (per-run (lambda () (encode receive-request env "the procedure")
                     (encode-arguments args)))
          (per-run (lambda () (hash-table-ref/default decode-cache 1 #f)))
          (per-run (lambda ()
                     (bare-encode receive-request) (bare-encode args))))
  (write-stages "sender" call-message)
  (let ((answer-text (text-of answer-message)))
    (stages "sender" answer-message answer-text (string->utf8 (signed answer-text))
            (lambda (parsed)
              (report "sender" "decode"
                      (per-run (lambda () (decode-value (list-ref parsed 2))))
                      (per-run (lambda () (list-ref parsed 2))))))))

;; The text, its MAC and the write: Murdoch writes each message to a text
;; port, checks its size, and signs it; the bare way writes the datum and
;; takes the text to sign.
(define (write-stages side message)
  (let ((text (text-of message)))
    (report side "message text"
            (per-run (lambda () (frame-text text-port message)))
            (per-run (lambda () (reset-output-string! text-port)
                       (write-simple message text-port)
                       (get-output-string text-port))))
    (report side "sign"
            (per-run (lambda () (signed text)))
            (per-run (lambda () (signed text))))
    ;; Murdoch's write is the bare one: the netstring, and the flush.
    (let* ((framed (signed text))
           (write (per-run (lambda () (write-netstring framed (cadr sink))
                             (flush-output-port (cadr sink))))))
      (report side "write" write write))))

;; The writes go to a socket of their own, which a thread empties as
;; they come, so that its buffer never fills.
(define sink (socket-pair))
(thread-start!
 (make-thread (lambda ()
                (let loop ()
                  (unless (eof-object? (read-netstring (car sink) 1048576))
                    (loop))))))

;;; The whole message: two live processes' CPU per message

(define troy (uid->aspace 'troy))

(define (callee-cpu-per-call)
  (define (calls n)
    (do ((i 0 (+ i 1))) ((= i n)) (apply remote-apply troy receive-request args)))
  (calls 300)
  (let ((t0 (process-cpu-us troy-pid)) (me0 (process-cpu-us (current-process-id))))
    (calls 3000)
    (list (/ (- (process-cpu-us troy-pid) t0) 3000)
          (/ (- (process-cpu-us (current-process-id)) me0) 3000))))

;; A forked bare Chibi echo server, waiting in ppoll as an address space
;; waits, and its CPU per echo.
(define (echo-cpu-per-message)
  (let* ((listener+port (listen-on-free-port))
         (pid (begin (flush-output-port) (fork))))
    (cond
     ((zero? pid)
      (echo-connection (car listener+port) (cdr listener+port) #f 1048576)
      (kill (current-process-id) signal/kill))
     (else
      (let* ((io (open-net-io "127.0.0.1" (cdr listener+port)))
             (in (cadr io)) (out (car (cddr io))))
        (define (echoes n)
          (do ((i 0 (+ i 1))) ((= i n))
            (write-netstring call-payload out)
            (flush-output-port out)
            (read-netstring in 1048576)))
        (echoes 300)
        (let ((t0 (process-cpu-us pid)) (me0 (process-cpu-us (current-process-id))))
          (echoes 3000)
          (let ((result (list (/ (- (process-cpu-us pid) t0) 3000)
                              (/ (- (process-cpu-us (current-process-id)) me0) 3000))))
            (kill pid signal/kill)
            (waitpid pid 0)
            result)))))))

(receiver-stages)
(sender-stages)
(let ((murdoch (callee-cpu-per-call))
      (bare (echo-cpu-per-message)))
  (report "receiver" "whole, live" (car murdoch) (car bare))
  (report "sender" "whole, live" (cadr murdoch) (cadr bare)))

(stop-all-processes!)
(remove-test-lab! lab)
