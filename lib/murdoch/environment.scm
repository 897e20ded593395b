;;;; The environment that received code runs in.
;;
;; It is the safety boundary of an address space: a peer that holds the
;; lab's key can run anything this environment can, and nothing more.  So
;; it has R7RS's computing libraries and Murdoch's interface, and none of
;; (scheme file), (scheme process-context), (scheme load), (scheme eval) or
;; (scheme repl).  The lab's code files are loaded into it, so that their
;; procedures are there to be called by name.

(define sandbox-libraries
  '((except (scheme base) lambda define) (scheme char) (scheme cxr)
    (scheme inexact) (scheme complex) (scheme lazy) (scheme case-lambda)
    (scheme write) (srfi 1) (srfi 18) (murdoch)))

;;> A fresh environment for received code, with the lab's code files
;;> loaded.  Each file is read here and evaluated in the environment, so
;;> the files themselves can use no more than received code can.
(define (make-lab-environment lab)
  (let ((env (apply mutable-environment sandbox-libraries)))
    (for-each (lambda (file) (load-into (lab-path lab file) env))
              (lab-code-files lab))
    env))

(define (lab-code-files lab)
  (cond ((assq 'code (lab-settings lab)) => cdr) (else '())))

;;> An environment for a person at a REPL: everything Chibi has, Murdoch,
;;> and the very procedures the lab's code defined in \var{lab-env}, so
;;> that they travel by name.
(define (make-repl-environment lab lab-env)
  (let ((env (mutable-environment '(except (scheme base) lambda define)
                          '(scheme char) '(scheme cxr) '(scheme inexact)
                          '(scheme complex) '(scheme lazy) '(scheme time)
                          '(scheme case-lambda) '(scheme write) '(scheme read)
                          '(scheme file) '(scheme process-context)
                          '(scheme eval) '(scheme load) '(srfi 1) '(srfi 18)
                          '(murdoch))))
    (for-each (lambda (file)
                (for-each (lambda (name)
                            (eval `(define ,name ',(eval name lab-env)) env))
                          (defined-names (lab-path lab file))))
              (lab-code-files lab))
    env))

(define (read-forms file)
  (call-with-input-file file
    (lambda (in)
      (let loop ((acc '()))
        (let ((form (read in)))
          (if (eof-object? form) (reverse acc) (loop (cons form acc))))))))

(define (load-into file env)
  (for-each (lambda (form) (eval form env)) (read-forms file)))

(define (defined-names file)
  (filter-map (lambda (form)
                (and (pair? form) (eq? (car form) 'define) (pair? (cdr form))
                     (if (pair? (cadr form)) (car (cadr form)) (cadr form))))
              (read-forms file)))
