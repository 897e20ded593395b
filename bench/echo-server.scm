;;;; One echo server of bench/scheme-pingpong.scm's fan-out floor.
;;
;; Usage: tools/chibi bench/echo-server.scm PORT poll|block
;;
;; Listens on 127.0.0.1:PORT, serves the first connection: reads a
;; netstring and writes it back until the peer closes.  "poll" waits in
;; ppoll through (murdoch sys scheduler), as an address space waits; "block"
;; reads in the kernel.  A file of its own, importing only what it uses:
;; started from bench/scheme-pingpong.scm, which imports (murdoch
;; testing), each server took 1.3 s of CPU to start instead of 0.3 s, 85 s
;; for a lab of 64 on two cores, and a loaded machine then had the first
;; server late past the sender's patience.

(import (scheme base) (scheme eval) (scheme process-context)
        (chibi net) (bench echo))

(define (serve port poll?)
  (let ((addr (get-address-info "127.0.0.1" port)))
    (echo-connection (make-listener-socket addr) port (not poll?) 64)))

(let* ((args (cdr (command-line)))
       (poll? (equal? (cadr args) "poll")))
  ;; Loading (murdoch sys scheduler) installs it.
  (if poll? (environment '(murdoch sys scheduler)))
  (serve (string->number (car args)) poll?))
