;;;; One echo server of bench/scheme-pingpong.scm's fan-out floor.
;;
;; Usage: tools/chibi bench/echo-server.scm PORT poll|block [GROUP GROUP-PORT]
;;
;; Listens on 127.0.0.1:PORT, serves the first connection: reads a
;; netstring and writes it back until the peer closes.  With a multicast
;; GROUP (poll only), it also joins it and writes each datagram's bytes
;; back on that connection, as an address space answers a multicast call.
;; "poll" waits in ppoll through (murdoch sys scheduler), as an address
;; space waits; "block" reads in the kernel.  A file of its own, importing
;; only what it uses: started from bench/scheme-pingpong.scm, which
;; imports (murdoch testing), each server took 1.3 s of CPU to start
;; instead of 0.3 s, 85 s for a lab of 64 on two cores, and a loaded
;; machine then had the first server late past the sender's patience.

(import (scheme base) (scheme eval) (scheme process-context)
        (chibi net) (murdoch wire multicast) (bench echo))

;; The group is joined before the port listens: the sender's first
;; datagram comes as soon as its connection is made.
(define (serve port poll? group)
  (let ((group-socket (and group (open-multicast-socket (car group) (cdr group)
                                                        "127.0.0.1")))
        (addr (get-address-info "127.0.0.1" port)))
    (echo-connection (make-listener-socket addr) port (not poll?) 64 group-socket)))

(let* ((args (cdr (command-line)))
       (poll? (equal? (cadr args) "poll")))
  ;; Loading (murdoch sys scheduler) installs it.
  (if poll? (environment '(murdoch sys scheduler)))
  (serve (string->number (car args)) poll?
         (and (pair? (cddr args))
              (cons (car (cddr args)) (string->number (cadr (cddr args)))))))
