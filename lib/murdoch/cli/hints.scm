;;;; Hints: the REPL's eval, for a person who typed something wrong.  Chibi
;;;; names the line an error was raised at, in its files or ours, not where
;;;; the person went wrong.  A hint for: code naming a REPL definition, a
;;;; value that cannot travel, a wrong number of arguments, an unknown name
;;;; or uid, and a call that timed out (docs/architecture.md).

;;> Evaluates \var{expr} in \var{env} as the REPL's eval, an error raised
;;> again without Chibi's or Murdoch's place, with a hint.
(define (eval-with-hints expr env)
  (guard (e ((and (exception? e) (arity-error? e)) (raise (arity-recast e)))
            ((and (exception? e) (undefined-variable e))
             => (lambda (name) (raise (undefined-recast name env))))
            ((and (exception? e) (unknown-uid e))
             => (lambda (uid) (raise (unknown-uid-recast e uid))))
            ((and (exception? e) (library-source? e))
             (raise (recast e (hint e env)))))
    (eval expr env)))

(define (library-source? e)
  (or (remote-error? e) (send-error? e)
      (let ((source (exception-source e)))
        (and (pair? source) (string? (car source))
             (or (string-contains (car source) "/lib/murdoch/")
                 (string-contains (car source) "/chibi/"))))))

;; e again, with no procedure or file, and hint after its message.
(define (recast e hint)
  (make-exception (exception-kind e)
                  (if hint
                      (string-append (error-object-message e) "\n  hint: " hint)
                      (error-object-message e))
                  (error-object-irritants e) #f #f))

(define (hint e env)
  (cond
   ((remote-timeout-error? e)
    (let ((uid (symbol->string (remote-error-uid e))))
      (string-append "the call may still be running on " uid ": a procedure that"
                     " never calls out (a loop, a long thread-sleep!) runs to its end,"
                     " and " uid " is busy with it until then")))
   ((send-error? e)
    (string-append "a value travels when it is data, or a procedure; make the"
                   " rest inside the procedure, where it runs"))
   ((and (remote-raised-error? e) (undefined-name (remote-error-message e)))
    => (lambda (name) (and (defined-here? name env) (definition-hint name e))))
   (else #f)))

(define (undefined-variable e)
  (and (equal? (error-object-message e) "undefined variable")
       (pair? (error-object-irritants e))
       (let ((name (car (error-object-irritants e))))
         (cond ((symbol? name) name)
               ((identifier? name) (identifier->symbol name))
               (else #f)))))

;; "troyy is not defined; did you mean 'troy, a uid?"
(define (undefined-recast name env)
  (let* ((text (symbol->string name))
         (uids (map symbol->string (known-uids)))
         (near-uid (nearest-name text uids))
         (near (nearest-name text (map symbol->string (visible-names env)))))
    (make-exception
     'undefined
     (string-append text " is not defined"
                    (cond ((member text uids)
                           (string-append "; " text " is a uid: quote it, '" text))
                          ((and near-uid (or (not near)
                                             (<= (edit-distance text near-uid)
                                                 (edit-distance text near))))
                           (string-append "; did you mean '" near-uid ", a uid?"))
                          (near (string-append "; did you mean " near "?"))
                          (else "")))
     '() #f #f)))

(define (nearest text names)
  (cond ((nearest-name text names)
         => (lambda (n) (string-append "; did you mean " n "?")))
        (else ";")))

;; "no address space troyy is known; did you mean troy?": in one line.
(define (unknown-uid-recast e uid)
  (make-exception (exception-kind e)
                  (string-append "no address space " (symbol->string uid) " is known"
                                 (nearest (symbol->string uid)
                                          (map symbol->string (known-uids)))
                                 " (known-uids) lists those that are")
                  '() #f #f))

(define (unknown-uid e)
  (and (equal? (error-object-message e) "no address space of this uid is known")
       (pair? (error-object-irritants e))
       (symbol? (car (error-object-irritants e)))
       (car (error-object-irritants e))))

(define (arity-error? e)
  (and (member (error-object-message e) '("not enough args" "too many args"))
       (= 2 (length (error-object-irritants e)))
       (procedure? (car (error-object-irritants e)))))

;; "remote-apply takes at least 2 arguments, and was given 1".
(define (arity-recast e)
  (let* ((p (car (error-object-irritants e)))
         (n (procedure-arity p)))
    (make-exception
     (exception-kind e)
     (string-append (let ((name (procedure-name p)))
                      (if (symbol? name) (symbol->string name) "the procedure"))
                    " takes " (if (procedure-variadic? p) "at least " "")
                    (arguments n) ", and was given "
                    (arguments (cadr (error-object-irritants e)))
                    "\n  hint: docs/reference.md says what each procedure of"
                    " (murdoch) takes")
     '() #f #f)))

(define (arguments n)
  (string-append (number->string n) (if (= n 1) " argument" " arguments")))

(define (undefined-name message)
  (let ((prefix "undefined variable "))
    (and (string? message)
         (> (string-length message) (string-length prefix))
         (string=? prefix (substring message 0 (string-length prefix)))
         (string->symbol (substring message (string-length prefix)
                                    (string-length message))))))

(define (defined-here? name env)
  (guard (e (#t #f)) (eval name env) #t))

(define (definition-hint name e)
  (let ((n (symbol->string name)))
    (string-append n " is defined at this REPL, and code sent to "
                   (symbol->string (remote-error-uid e))
                   " sees only (murdoch) and the lab's code: define " n
                   " inside the procedure, pass its value as an argument,"
                   " or put it in the lab's code file")))

(define (string-contains s part)
  (let ((n (string-length part)))
    (let loop ((i 0))
      (and (<= (+ i n) (string-length s))
           (or (string=? part (substring s i (+ i n))) (loop (+ i 1)))))))
