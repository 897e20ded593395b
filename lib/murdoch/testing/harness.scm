;;;; What the multi-process tests share: labs on free ports, children stopped.

;; The repository: MURDOCH_TOP, as tests/run sets it, else the current folder.
(define top
  (or (get-environment-variable "MURDOCH_TOP") (current-directory)))

;; The lab file's port base rules; an exported one would move only this process.
(unsetenv "MURDOCH_PORT_BASE")

;; A write to a dead child raises, rather than SIGPIPE ending the test unreported.
(set-signal-action! signal/pipe #f)

;;> The path of a file of the repository.
(define (tool-path rel) (string-append top "/" rel))

(define-record-type test-lab
  (%make-test-lab file directory port-base)
  test-lab?
  (file test-lab-file)
  (directory test-lab-directory)
  (port-base test-lab-port-base))

;; The first line \var{cmd} prints, else an error with its wait status.
;; Not call-with-process-io, whose close-file-descriptor leaves the
;; collector to close the numbers again later, by then others'.
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

;;> A fresh folder under $TMPDIR for its owner alone, as mktemp -d makes.
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

;;> A port base B, free from B to B + 199, held while this process lives
;;> and \var{folder}, if given, exists.
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

;;> The message of the error \var{thunk} raises, or no-error.
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

;;> Every file under \var{folder}, in its folders too, whose name ends
;;> with \var{suffix}.
(define (files-under folder suffix)
  (append-map (lambda (f)
                (let ((path (string-append folder "/" f)))
                  (cond ((member f '("." "..")) '())
                        ((file-directory? path) (files-under path suffix))
                        ((string-suffix? suffix f) (list path))
                        (else '()))))
              (directory-files folder)))

;;> Writes a lab file of \var{clauses} and \var{files} in a fresh folder, on a free port base.
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

;;> Removes the lab's folder, after a failure showing each log's last lines.
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

;; Global: the test process's children, all stopped at its end.
(define *children* '())

;;> Starts \var{args} logging to \var{log-file}; answers the pid.
(define (start-process! args log-file)
  (let* ((parent (current-process-id))
         (pid (fork)))
    (cond
     ((zero? pid)
      ;; A test or bench killed, by a person or a time limit, leaves no
      ;; lab behind: its children die with it.
      (die-with-parent! parent signal/term)
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

;;> Asks \var{pid} to stop (SIGTERM) and waits; answers its wait status.
(define (stop-process! pid)
  (kill pid signal/term)
  (reap! pid))

;;> Kills \var{pid} at once (SIGKILL), as a crash would, and waits for it.
(define (kill-process! pid)
  (kill pid signal/kill)
  (reap! pid))

(define (stop-all-processes!)
  (for-each stop-process! *children*))

;;> Waits until \var{thunk} answers true, for at most \var{seconds}; its last value.
(define (wait-until seconds thunk)
  (let loop ((left (* seconds 20)))
    (or (thunk)
        (and (> left 0)
             (begin (thread-sleep! 0.05) (loop (- left 1)))))))

;;> Starts address space \var{uid} of the test lab; answers its pid once it listens.
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

;;> Starts `bin/murdoch lab` with \var{args}, output to \var{out}; its pid
;;> once ready, else an error with its output.
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
                           (reaped-if-ended! pid)))))
    (if (not (text-contains? (file-text out) "lab: ready"))
        (begin (if (memv pid *children*) (stop-process! pid))
               (error "the lab did not start" (file-text out))))
    pid))

;;> The median seconds of \var{runs} calls of \var{thunk}, as the benches measure.
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

;;> A loopback TCP listener on a port of its own, (listener . port): keep
;;> the listener while in use, as the collector closes a fileno nothing
;;> refers to.  Drawn at random from spare-ports, so runs at once differ.
(define (listen-on-free-port)
  (let-values (((low high) (spare-ports)))
    (let ((n (- high low)))
      (let try ((tries 0) (port (+ low (random-below n))))
        (cond
         ((= tries n) (error "listen-on-free-port: every port taken" low high))
         ((listener-on port) => (lambda (sock) (cons sock port)))
         (else (try (+ tries 1) (+ low (modulo (- (+ port 1) low) n)))))))))

;; The ports [low, high) that neither labs (tools/free-port-base) nor the kernel hand out.
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

;; A listener on 127.0.0.1:port, or #f when taken; a failed socket is
;; closed through a port (see command-output).
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
