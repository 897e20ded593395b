;;;; Starting an address space, and the thesis's aux.scm helpers.
;;
;; The remote layer, bottom to top: the wire (frame.scm, the protocol and
;; its message kinds), address spaces (aspace.scm), calls
;; (connection.scm, worker.scm, call.scm), the lab's multicast group
;; (group.scm), serving calls (serve.scm), proxies (proxy.scm) and
;; delivery to the whole lab (delivery.scm).  This library starts them,
;; in that order, and is what the layers above import.

;;> Makes this process the address space \var{uid} of \var{lab} (a lab
;;> record, see read-lab), with \var{environment} as the environment that
;;> received code runs in, and starts answering calls.  \var{port} may
;;> override the lab's port for uid.
(define (start-aspace! lab uid environment . port)
  (let ((entry (lab-aspace-by-uid lab uid)))
    (join-lab! lab uid
               (if entry (lab-aspace-host entry) (lab-setting lab 'interface))
               (cond ((pair? port) (car port))
                     (entry (lab-aspace-port entry))
                     (else (error "not in the lab" uid)))
               environment
               (make-decoder environment decode-proxy))
    (set-log-name! (string-append "murdoch " (symbol->string uid)))
    (start-wire! lab)
    (set-value-limits! lab)
    (set-sandbox-ports! (current-output-port) (current-error-port))
    (start-serving! lab)
    (spawn prober 'prober)
    (start-group! lab serve-group)
    (local-aspace)))

;;; From aux.scm

;;> Evaluates \var{var} in the address space \var{uid}.
(define-syntax var-ref
  (syntax-rules ()
    ((var-ref uid var)
     (remote-apply (uid->aspace uid) (sendable-lambda () var)))))

;;> Assigns \var{value} (evaluated here) to \var{var} in address space
;;> \var{uid}.
(define-syntax var-set!
  (syntax-rules ()
    ((var-set! uid var value)
     (let ((v value))
       (remote-apply (uid->aspace uid) (sendable-lambda () (set! var v)))))))

;;> Displays \var{string} on the standard output of address space \var{uid}.
(define (display-remote uid string)
  (remote-run! (uid->aspace uid)
               (sendable-lambda ()
                 (display string) (newline) (flush-output-port))))
