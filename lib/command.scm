;;;; bin/murdoch: start address spaces, join a lab at a REPL.

;;> Makes this process address space \var{uid} of the lab at
;;> \var{lab-file}, or of \var{lab} when it is already read, and starts
;;> serving with its subscriptions and monitors; answers the environment
;;> received code runs in.
(define (join-lab lab-file uid . port)
  (join-read-lab (read-lab lab-file) uid port))

(define (join-read-lab lab uid port)
  (let ((env (make-lab-environment lab)))
    (apply start-aspace! lab uid env port)
    (initialize-subscriptions! lab (lab-aspace-by-uid lab uid))
    env))

;;> `murdoch aspace LAB NAME`: be address space NAME until killed.
(define (run-aspace lab-file uid)
  (join-lab lab-file uid)
  (log-note "listening on " (aspace-host (local-aspace)) ":"
            (aspace-port (local-aspace)))
  (let wait () (thread-sleep! 3600) (wait)))

;;> `murdoch repl LAB [NAME]`: join the lab and read-eval-print.
(define (run-repl lab-file uid)
  (let* ((lab (read-lab lab-file))
         (guest? (not uid))
         (uid (or uid (string->symbol
                       (string-append "guest-" (number->string
                                                (current-process-id))))))
         (lab-env (join-read-lab lab uid
                                 (if guest? (list (lab-guest-port lab)) '()))))
    ;; (chibi repl) is loaded here, not imported: it costs seconds, and
    ;; only a person at a REPL needs it.
    ((eval 'repl (environment '(chibi repl)))
          'environment: (make-repl-environment lab lab-env)
          'raw?: (not (is-a-tty? (current-input-port)))
          'make-prompt: (lambda (module)
                          (string-append (symbol->string uid) "> ")))
    (exit 0)))
