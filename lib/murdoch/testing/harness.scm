;;;; What the multi-process tests share: labs in temporary folders on free
;;;; ports, and child processes that are always stopped.

;; The repository: MURDOCH_TOP, as tests/run sets it, else the current
;; folder, which is where tests/run and bench/run work.
(define top
  (or (get-environment-variable "MURDOCH_TOP") (current-directory)))

;; The lab file's port base rules in tests; an exported MURDOCH_PORT_BASE
;; would move this process and not its children.
(unsetenv "MURDOCH_PORT_BASE")

;; A test writes to children that may have died: a REPL past its time
;; limit, an address space it killed.  SIGPIPE's default action would end
;; the test without its summary, so it is ignored and the write raises,
;; which the test reports.
(set-signal-action! signal/pipe #f)

;;> The path of a file of the repository.
(define (tool-path rel) (string-append top "/" rel))

(define-record-type test-lab
  (%make-test-lab file directory port-base)
  test-lab?
  (file test-lab-file)
  (directory test-lab-directory)
  (port-base test-lab-port-base))

;; The first line \var{cmd} prints; an error when it prints none, which
;; gives how it ended (its wait status: 9 for SIGKILL, 256 for exit 1).
;; (chibi process)'s call-with-process-io will not do: it closes the
;; parent's ends of its pipes with close-file-descriptor, which leaves
;; their filenos marked open, and the collector later closes those
;; numbers again -- by then another pipe's or a live socket's.  Closing
;; through a port marks the fileno closed.
(define (command-output cmd)
  (let* ((pipe (open-pipe))
         (pid (fork)))
    (cond
     ((zero? pid)
      (duplicate-file-descriptor-to (cadr pipe) 1)
      (execute (car cmd) cmd)
      (exit 127))
     (else
      (close-port (open-output-file-descriptor (cadr pipe)))
      (let ((out (open-input-file-descriptor (car pipe))))
        (if (negative? pid)
            (begin (close-port out) (error "cannot fork for" cmd)))
        (let ((line (read-line out)))
          (close-port out)
          (let ((status (cadr (waitpid pid 0))))
            (if (eof-object? line)
                (error "a command printed nothing; its wait status:" cmd status))
            line)))))))

;;> A fresh folder of its own under $TMPDIR, readable by its owner alone,
;;> as mktemp -d makes one but with no process to start: this process's
;;> id and a count name it, and a name a process before took is passed.
(define (temporary-directory)
  (let ((base (or (get-environment-variable "TMPDIR") "/tmp")))
    (let loop ((tries 0))
      (set! folders-made (+ folders-made 1))
      (let ((dir (string-append base "/murdoch-test."
                                (number->string (current-process-id)) "."
                                (number->string folders-made))))
        (cond ((create-directory dir #o700) dir)
              ((< tries 100) (loop (+ tries 1)))
              (else (error "cannot make a folder" dir
                           (integer->error-string (errno)))))))))

(define folders-made 0)

;;> A port base B such that nothing listens on B to B + 199, claimed for
;;> as long as this process lives, or, given a \var{folder}, as long as
;;> that folder exists (tools/free-port-base).
(define (free-port-base . folder)
  (string->number (command-output (cons (tool-path "tools/free-port-base") folder))))

;;> The whole text of \var{file}, or "" when there is none yet.
(define (file-text file)
  (if (file-exists? file)
      (call-with-input-file file
        (lambda (in) (let ((s (read-string 10000000 in))) (if (eof-object? s) "" s))))
      ""))

;;> The lines of \var{file}, without their newlines.
(define (read-lines file)
  (call-with-input-file file port-lines))

;;> The lines of the string \var{text}, without their newlines.
(define (text-lines text)
  (port-lines (open-input-string text)))

(define (port-lines in)
  (let loop ((acc '()))
    (let ((line (read-line in)))
      (if (eof-object? line) (reverse acc) (loop (cons line acc))))))

;;> The message of the error \var{thunk} raises -- of a remote-error, the
;;> one it carries from the other address space -- or no-error.
(define (error-text thunk)
  (guard (e ((remote-error? e) (remote-error-message e))
            ((error-object? e) (error-object-message e)))
    (thunk)
    'no-error))

;;> True when \var{word} occurs in \var{text}.
(define (text-contains? text word)
  (let ((n (string-length word)))
    (let loop ((i 0))
      (and (<= (+ i n) (string-length text))
           (or (string=? word (substring text i (+ i n))) (loop (+ i 1)))))))

;;> Writes a lab file with \var{clauses} into a fresh temporary folder, on
;;> a port base no other lab on this machine is using.  \var{files} is a
;;> list of (name . text) written beside it (code files).
(define (make-test-lab clauses . files)
  (let* ((dir (temporary-directory))
         (base (free-port-base dir))
         (file (string-append dir "/lab.scm")))
    (call-with-output-file file
      (lambda (out)
        (write-simple `(lab test (port-base ,base) ,@clauses) out)
        (newline out)))
    (for-each (lambda (f)
                (call-with-output-file (string-append dir "/" (car f))
                  (lambda (out) (write-string (cdr f) out))))
              (if (pair? files) (car files) '()))
    (%make-test-lab file dir base)))

;;> Removes the lab's folder.  When a test of this process has failed, the
;;> last lines of each log in it go to standard error first: an address
;;> space that died in a CI run leaves no other trace.
(define (remove-test-lab! lab)
  (if (positive? (test-failure-count))
      (show-log-tails (test-lab-directory lab) 30))
  (delete-file-hierarchy (test-lab-directory lab)))

(define (show-log-tails dir n)
  (for-each
   (lambda (name)
     (let ((k (string-length name)))
       (when (and (> k 4) (string=? (substring name (- k 4) k) ".log"))
         (let ((lines (read-lines (string-append dir "/" name))))
           (display (string-append "--- the last lines of " name ":\n")
                    (current-error-port))
           (for-each (lambda (line)
                       (display (string-append line "\n") (current-error-port)))
                     (list-tail lines (max 0 (- (length lines) n))))))))
   (directory-files dir)))

(define *children* '())

;;> Starts \var{args} (a command and its arguments) with its output going
;;> to \var{log-file}; answers the pid.  The environment variable
;;> MURDOCH_PORT_BASE is cleared for it, so the lab file rules.
(define (start-process! args log-file)
  (let ((pid (fork)))
    (cond
     ((zero? pid)
      (execute "/bin/sh"
               (append (list "/bin/sh" "-c"
                             "unset MURDOCH_PORT_BASE; exec \"$@\" >>\"$0\" 2>&1"
                             log-file)
                       args))
      (exit 127))
     (else
      (set! *children* (cons pid *children*))
      pid))))

;;> Waits for \var{pid} to end; answers its wait status, 0 for a clean exit.
(define (reap! pid)
  (let ((status (cadr (waitpid pid 0))))
    (set! *children* (remove-pid pid *children*))
    status))

;; Whether \var{pid} has ended; if so it is reaped, as reap! would.
(define (reaped-if-ended! pid)
  (and (positive? (car (waitpid pid wait/no-hang)))
       (begin (set! *children* (remove-pid pid *children*)) #t)))

(define (remove-pid pid ls)
  (cond ((null? ls) '()) ((= pid (car ls)) (cdr ls))
        (else (cons (car ls) (remove-pid pid (cdr ls))))))

;;> Asks \var{pid} to stop (SIGTERM) and waits for it; answers its wait
;;> status.
(define (stop-process! pid)
  (kill pid signal/term)
  (reap! pid))

;;> Kills \var{pid} at once (SIGKILL), as a crash would, and waits for it.
(define (kill-process! pid)
  (kill pid signal/kill)
  (reap! pid))

(define (stop-all-processes!)
  (for-each stop-process! *children*))

;;> Waits until \var{thunk} answers true, checking every 50 ms, for at most
;;> \var{seconds}; answers its last value.
(define (wait-until seconds thunk)
  (let loop ((left (* seconds 20)))
    (or (thunk)
        (and (> left 0)
             (begin (thread-sleep! 0.05) (loop (- left 1)))))))

;;> Starts address space \var{uid} of the test lab as a process of its own,
;;> logging to UID.log in the lab's folder, and waits until it listens;
;;> answers its pid.
(define (start-lab-aspace! lab uid)
  (let* ((entry (lab-aspace-by-uid (read-lab (test-lab-file lab)) uid))
         (pid (start-process!
               (list (tool-path "bin/murdoch") "aspace" (test-lab-file lab)
                     (symbol->string uid))
               (string-append (test-lab-directory lab) "/"
                              (symbol->string uid) ".log"))))
    (if (not (wait-for-port (lab-aspace-port entry) 60))
        (error "an address space did not start; see its log" uid
               (test-lab-directory lab)))
    pid))

;;> Starts `bin/murdoch lab` with \var{args} (the lab file and options),
;;> its output going to \var{out}, and answers its pid once it says it is
;;> ready.  If it gives up instead, it is stopped and an error raised that
;;> holds its output.  \var{port-base}, if given, is the MURDOCH_PORT_BASE
;;> it runs with.
(define (start-murdoch-lab! args out . port-base)
  (let ((pid (start-process!
              (append (if (pair? port-base)
                          (list "env" (string-append "MURDOCH_PORT_BASE="
                                                     (number->string (car port-base))))
                          '())
                      (list (tool-path "bin/murdoch") "lab")
                      args)
              out)))
    (wait-until 90 (lambda ()
                     (let ((text (file-text out)))
                       (or (text-contains? text "lab: ready")
                           (text-contains? text "stopping the lab")
                           (text-contains? text "ERROR")
                           ;; A usage error, say, says no ERROR.
                           (reaped-if-ended! pid)))))
    (if (not (text-contains? (file-text out) "lab: ready"))
        (begin (if (memv pid *children*) (stop-process! pid))
               (error "the lab did not start" (file-text out))))
    pid))

;;> The median time in seconds of \var{runs} calls of \var{thunk}: the
;;> benches' measure, so that a few calls delayed by the machine's other
;;> work do not move it.
(define (median-seconds runs thunk)
  (let loop ((i 0) (times '()))
    (if (= i runs)
        (list-ref (list-sort < times) (quotient runs 2))
        (let ((t0 (current-second)))
          (thunk)
          (loop (+ i 1) (cons (- (current-second) t0) times))))))

;;> Waits until something accepts connections on \var{port}.
(define (wait-for-port port seconds)
  (wait-until seconds
    (lambda ()
      (let ((io (open-connection "127.0.0.1" port seconds)))
        (and (pair? io)
             (begin (close-input-port (car io))
                    (close-output-port (cadr io))
                    #t))))))

;;> A loopback TCP listener on a port of its own, for a test or bench
;;> that serves on one socket without a lab; answers (listener . port).
;;> The listener is a fileno for \scheme{accept}, non-blocking as Chibi's
;;> threads want (the \scheme{bind} and \scheme{listen} of (chibi net)
;;> make it so).  Keep the listener itself, not only its port, for as
;;> long as it is used: the collector closes a fileno nothing refers to.
;;>
;;> The port is drawn at random between the test labs' port bases and
;;> the kernel's ephemeral range (see \scheme{spare-ports}); one that
;;> another process holds is stepped over, so that runs at once each get
;;> a port of their own.
(define (listen-on-free-port)
  (let-values (((low high) (spare-ports)))
    (let ((n (- high low)))
      (let try ((tries 0) (port (+ low (random-below n))))
        (cond
         ((= tries n) (error "listen-on-free-port: every port taken" low high))
         ((listener-on port) => (lambda (sock) (cons sock port)))
         (else (try (+ tries 1) (+ low (modulo (- (+ port 1) low) n)))))))))

;; The ports [low, high) that nothing else of ours, nor the kernel, hands
;; out: tools/free-port-base puts lab port bases at 10000 + 200k, each
;; taking 200 ports, for as many k as fit below the ephemeral range, where
;; the kernel picks the local ports of outgoing connections.  From the top
;; lab's end to the start of that range are 200 to 399 spare ports.
(define (spare-ports)
  (let* ((high (ephemeral-port-start))
         (low (+ 10000 (* 200 (quotient (- high 10200) 200)))))
    (if (< high 10200)
        (error "the ephemeral port range starts too low for test labs" high))
    (values low high)))

(define (ephemeral-port-start)
  (let ((n (guard (e (#t #f))
             (call-with-input-file "/proc/sys/net/ipv4/ip_local_port_range"
               read))))
    (if (exact-integer? n) n 32768)))

(define (random-below n)
  (call-with-port (open-binary-input-file "/dev/urandom")
    (lambda (in)
      (let ((b (read-bytevector 2 in)))
        (modulo (+ (* 256 (bytevector-u8-ref b 0)) (bytevector-u8-ref b 1))
                n)))))

(define eaddrinuse 98)          ; Linux's EADDRINUSE, which Chibi does not name

;; A listener on 127.0.0.1:port, or #f when another socket has the port.
;; (chibi net)'s make-listener-socket will not do for trying ports: when
;; bind fails it closes the socket with close-file-descriptor, which leaves
;; the fileno marked open, and the collector later closes that number
;; again -- by then the number of the next socket made, the listener that
;; did bind, and accept on it answers #f.  Here a socket that fails is
;; closed through a port, which marks its fileno closed.
(define (listener-on port)
  (let* ((addr (get-address-info "127.0.0.1" port))
         (sock (socket (address-info-family addr)
                       (address-info-socket-type addr)
                       (address-info-protocol addr))))
    (if (not sock)
        (error "listen-on-free-port: no socket" (integer->error-string (errno))))
    (let* ((ok (and (set-socket-option! sock level/socket socket-opt/reuseaddr 1)
                    (bind sock (address-info-address addr)
                          (address-info-address-length addr))
                    ;; Two sockets with SO_REUSEADDR may both bind a port
                    ;; that neither listens on yet; the second listen fails.
                    (listen sock 128)))
           (err (errno)))
      (cond
       (ok sock)
       (else
        (close-port (open-input-file-descriptor sock))
        (if (= err eaddrinuse)
            #f
            (error "listen-on-free-port: cannot listen on" port
                   (integer->error-string err))))))))
