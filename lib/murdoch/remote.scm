;;;; Starting an address space, and the thesis's aux.scm helpers.  The
;;;; layer bottom to top: the wire, address spaces (remote/aspace.scm), calls
;;;; (connection, worker, call), the group, serving, proxies and delivery;
;;;; start-aspace! starts them in that order.

;;> Makes this process the address space \var{uid} of its lab, received
;;> code running in \var{environment}, and starts answering calls;
;;> \var{port} may override the lab's port for uid.
(define (start-aspace! uid environment . port)
  (let ((entry (lab-aspace-by-uid (current-lab) uid)))
    (join-lab! uid
               (if entry (lab-aspace-host entry) (setting 'interface))
               (cond ((pair? port) (car port))
                     (entry (lab-aspace-port entry))
                     (else (error "not in the lab" uid)))
               environment
               (make-decoder environment decode-proxy))
    (set-log-name! (string-append "murdoch " (symbol->string uid)))
    (start-wire!)
    (open-connections!)
    (set-value-limits!)
    (set-sandbox-ports! (current-output-port) (current-error-port))
    (start-serving!)
    (spawn prober 'prober)
    (start-group! serve-group)
    (local-aspace)))

;;; From aux.scm

;;> Evaluates \var{var} in the address space \var{uid}.
(define-syntax var-ref
  (syntax-rules ()
    ((var-ref uid var)
     (remote-apply (uid->aspace uid) (sendable-lambda () var)))))

;;> Assigns \var{value} (evaluated here) to \var{var} in address space \var{uid}.
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
