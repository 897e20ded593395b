;;;; One echo server of bench/scheme-pingpong.scm's fan-out floor.
;;
;; Usage: tools/chibi bench/echo-server.scm PORT poll|block
;;
;; Listens on 127.0.0.1:PORT, serves the first connection: reads a
;; netstring and writes it back until the peer closes.  "poll" waits in
;; ppoll through (murdoch scheduler), as an address space waits; "block"
;; reads in the kernel.  A file of its own, importing only what it uses:
;; started from bench/scheme-pingpong.scm, which imports (murdoch
;; testing), each server took 1.3 s of CPU to start instead of 0.3 s, 85 s
;; for a lab of 64 on two cores, and a loaded machine then had the first
;; server late past the sender's patience.

(import (scheme base) (scheme eval) (scheme process-context) (srfi 151)
        (chibi net) (chibi filesystem)
        (murdoch netstring))

(define max-frame 64)

(define (serve port poll?)
  (let* ((addr (get-address-info "127.0.0.1" port))
         (listener (make-listener-socket addr))
         (sock (accept listener (address-info-address addr)
                       (address-info-address-length addr)))
         (in (open-input-file-descriptor sock))
         (out (open-output-file-descriptor sock)))
    ;; Then a read that finds nothing waits in the kernel, as in C, not in
    ;; Chibi's scheduler.
    (if (not poll?)
        (set-file-descriptor-status!
         sock (bitwise-and (get-file-descriptor-status sock)
                           (bitwise-not open/non-block))))
    (let loop ()
      (let ((frame (read-netstring in max-frame)))
        (unless (eof-object? frame)
          (write-netstring frame out)
          (flush-output-port out)
          (loop))))))

(let* ((args (cdr (command-line)))
       (poll? (equal? (cadr args) "poll")))
  ;; Loading (murdoch scheduler) installs it.
  (if poll? (environment '(murdoch scheduler)))
  (serve (string->number (car args)) poll?))
