;;;; The sandbox: where received code runs, the address space's safety
;;;; boundary (docs/security.md); each of its rules is kept here.

(define sandbox-libraries
  '((except (scheme base) lambda define set! make-vector make-string
            make-bytevector make-list read-bytevector expt)
    (scheme char) (scheme cxr)
    (scheme inexact) (scheme complex) (scheme lazy) (scheme case-lambda)
    (scheme write) (except (srfi 1) make-list list-tabulate iota)
    (except (srfi 18) thread-terminate! make-thread) (murdoch)
    (rename (only (murdoch code sandbox) guarded-set! guarded-thread-terminate!
                  make-logged-thread sized-make-vector sized-make-string
                  sized-make-bytevector sized-make-list sized-list-tabulate
                  sized-iota sized-read-bytevector sized-expt)
            (guarded-set! set!)
            (guarded-thread-terminate! thread-terminate!)
            (make-logged-thread make-thread)
            (sized-make-vector make-vector) (sized-make-string make-string)
            (sized-make-bytevector make-bytevector) (sized-make-list make-list)
            (sized-list-tabulate list-tabulate) (sized-iota iota)
            (sized-read-bytevector read-bytevector) (sized-expt expt))))

;;; Assignment

;; Global, read by guarded-set! as code compiles: environments whose imports are guarded.
(define *guarded* '())

;;> Murdoch's set! inside the sandbox: an error at compile time for a
;;> binding imported from a library, else an ordinary set!.
(define-syntax guarded-set!
  (lambda (expr use-env mac-env)
    (let ((target (and (pair? (cdr expr)) (cadr expr))))
      (if (and (identifier? target) (imported? use-env target))
          (error (string-append "set!: " (symbol->string (identifier->symbol target))
                                " is imported, and cannot be assigned here")))
      (cons (make-syntactic-closure mac-env '() 'set!) (cdr expr)))))

(define (imported? use-env id)
  (let ((cell (env-cell use-env id)))
    (and cell
         (any (lambda (env)
                (eq? cell (env-cell (env-parent env) (identifier->symbol id))))
              *guarded*))))

;;; Threads

;; Global, as any layer's thread may serve calls.
(define *protected* (make-hash-table eq?))
(define *protected-lock* (make-mutex 'protected))

(define (protect! thread on?)
  (lock! *protected-lock*)
  (if on?
      (hash-table-set! *protected* thread #t)
      (hash-table-delete! *protected* thread))
  (unlock! *protected-lock*))

;;> A thread, as make-thread makes, that received code cannot end.
(define (make-guarded-thread thunk name)
  (make-logged-thread (lambda ()
                        (protect! (current-thread) #t)
                        (dynamic-wind (lambda () #f)
                                      thunk
                                      (lambda () (protect! (current-thread) #f))))
                      name))

;;> make-thread inside the sandbox: a raise that ends the thread is logged
;;> in one line, and thread-join! raises it as before.
(define (make-logged-thread thunk . name)
  (apply make-thread
         (lambda ()
           (guard (e (#t (log-thread-death e) (raise e)))
             (thunk)))
         name))

;; Chibi writes a thread's uncaught error and backtrace to its error port,
;; made a sink so the line logged here is the only one.
(define (log-thread-death e)
  (parameterize ((current-error-port (process-port sandbox-err (current-error-port))))
    (log-warn "thread " (thread-label (current-thread)) " died: " (error-message e)))
  (thread-parameters-set! (cons (cons current-error-port (open-output-string))
                                (thread-parameters))))

(define (thread-label thread)
  (let ((name (thread-name thread)))
    (if name
        (call-with-output-string (lambda (out) (write name out)))
        "without a name")))

;;; Allocation

;; The lab's max-alloc and the process's ports received code writes to.
(define-record-type sandbox
  (make-sandbox max-alloc out err)
  sandbox?
  (max-alloc sandbox-max-alloc)         ; bytes
  (out sandbox-out sandbox-out-set!)
  (err sandbox-err sandbox-err-set!))

;; The node's sandbox part, for every call the process serves; #f before
;; the lab's code is loaded.
(define (the-sandbox) (and *node* (node-sandbox *node*)))

(define (check-alloc! who count unit)
  (let ((most (and (the-sandbox) (sandbox-max-alloc (the-sandbox)))))
    (if (and most (real? count) (> (* count unit) most))
        (error (string-append who ": " (number->string count)
                              " would take more than the lab's max-alloc, "
                              (number->string most) " bytes")))))

(define (sized who unit make)
  (lambda (count . rest)
    (check-alloc! who count unit)
    (apply make count rest)))

;; In Chibi a vector's slot and a pair each take a word or more.
(define sized-make-vector (sized "make-vector" 8 make-vector))
(define sized-make-bytevector (sized "make-bytevector" 1 make-bytevector))
(define sized-make-list (sized "make-list" 32 make-list))
(define sized-list-tabulate (sized "list-tabulate" 32 list-tabulate))
(define sized-iota (sized "iota" 32 iota))
(define sized-read-bytevector (sized "read-bytevector" 1 read-bytevector))

(define (sized-make-string count . fill)
  (check-alloc! "make-string" count
                (if (and (pair? fill) (char? (car fill)))
                    (bytevector-length (string->utf8 (string (car fill))))
                    1))
  (apply make-string count fill))

;; An exact power takes as many bits as its exponent times its base's.
(define (sized-expt base power)
  (if (and (number? base) (number? power) (exact? base) (exact? power)
           (rational? base) (integer? power) (> (abs power) 1))
      (let ((digits (max (abs (numerator base)) (denominator base))))
        (if (> digits 1)
            (check-alloc! "expt" (abs power) (/ (log digits 2) 8)))))
  (expt base power))

;;> thread-terminate! inside the sandbox: not for the threads that serve calls.
(define (guarded-thread-terminate! thread)
  (if (hash-table-ref/default *protected* thread #f)
      (error "thread-terminate!: this thread serves calls, and a call cannot end it"))
  (thread-terminate! thread))

;;; Each call's own ports and parameters

;;> Gives the process's standard output and error, for received code to write to.
(define (set-sandbox-ports! out err)
  (sandbox-out-set! (the-sandbox) out)
  (sandbox-err-set! (the-sandbox) err))

;; The process's port, by which (sandbox-out or sandbox-err), else current.
(define (process-port which current)
  (or (and (the-sandbox) (which (the-sandbox))) current))

;; A port that writes through to port, closable alone, flushed at each call's end.
(define (through-port port)
  (make-custom-output-port
   (lambda (str start end)
     (write-string str port start end)
     (flush-output-port port)
     (- end start))))

;; The ports of a thread's calls, its specific, in a record received code
;; cannot make: a worker's next call never writes to an earlier one's ports.
(define-record-type call-ports
  (make-call-ports in out err)
  call-ports?
  (in call-ports-in)
  (out call-ports-out)
  (err call-ports-err))

(define (thread-call-ports)
  (let ((p (thread-specific (current-thread))))
    (if (and (call-ports? p) (port-open? (call-ports-in p))
             (port-open? (call-ports-out p)) (port-open? (call-ports-err p)))
        p
        (let ((new (make-call-ports
                    (make-null-input-port)
                    (through-port (process-port sandbox-out (current-output-port)))
                    (through-port (process-port sandbox-err (current-error-port))))))
          (thread-specific-set! (current-thread) new)
          new))))

(define-syntax flush-if-open
  (syntax-rules () ((_ port) (if (port-open? port) (flush-output-port port)))))

;; Global: each layer adds its own as it loads (sandbox-parameter!).
(define *parameters* '())

;;> Gives each received call its own binding of \var{parameter}, such as
;;> remote-timeout, so a call setting it sets nothing for the process.
(define (sandbox-parameter! parameter)
  (set! *parameters* (cons parameter *parameters*)))

;;> Applies \var{proc} to \var{args} as a received call runs, with its own
;;> ports and bindings of the sandbox's parameters; a raise leaves both to
;;> the handler around it.  parameterize without dynamic-wind (docs/speed.md).
(define (call-in-sandbox proc args)
  (sandboxed (thread-call-ports) (thread-parameters) proc args))

(define-syntax flush-ports
  (syntax-rules ()
    ((_ p) (begin (flush-if-open (call-ports-out p)) (flush-if-open (call-ports-err p))))))

;; fresh-bindings is C (call-bindings.c).
(define-syntax call-bindings
  (syntax-rules ()
    ((_ p outer)
     (fresh-bindings *parameters*
                     (cons (cons current-input-port (call-ports-in p))
                           (cons (cons current-output-port (call-ports-out p))
                                 (cons (cons current-error-port (call-ports-err p))
                                       outer)))))))

(define (sandboxed p outer proc args)
  (thread-parameters-set! (call-bindings p outer))
  (left-sandbox p outer (apply proc args)))

(define (left-sandbox p outer value)
  (thread-parameters-set! outer)
  (flush-ports p)
  value)

;;> Flushes the ports of this thread's calls, for the handler of one that raised.
(define (flush-call-ports!)
  (let ((p (thread-specific (current-thread))))
    (if (call-ports? p) (flush-ports p))))

;;; Making the environments

;;> A fresh environment for received code, the code files of this
;;> process's lab evaluated in it.
(define (make-lab-environment)
  (node-sandbox-set! (this-node) (make-sandbox (setting 'max-alloc) #f #f))
  (let ((env (apply mutable-environment sandbox-libraries))
        (lab (current-lab)))
    (set! *guarded* (cons env *guarded*))
    (for-each (lambda (file) (load-into (lab-path lab file) env))
              (lab-code-files lab))
    env))

;;> Raises for the first name the lab's code files use but neither define
;;> nor import, naming file, line and nearest name, lest a robot find it.
(define (check-lab-code lab env)
  (let ((undefined (undefined-names env)))
    (if (pair? undefined)
        (for-each (lambda (file)
                    (let ((path (lab-path lab file)))
                      (for-each (lambda (entry) (check-uses path entry undefined env))
                                (car (read-source path)))))
                  (lab-code-files lab)))))

(define (check-uses file entry undefined env)
  (let ((name (find (lambda (name) (mentions? (car entry) name)) undefined)))
    (if name
        (error (form-line-text file entry
                               (string-append (symbol->string name)
                                              " is used but not defined"
                                              (nearest-defined name env)))))))

;; The names that code compiled in env refers to and nothing defines.
(define (undefined-names env)
  (let ((out (open-output-string)))
    (parameterize ((current-error-port out))
      (warn-undefs env #f #f))
    (let ((in (open-input-string (get-output-string out))))
      (let loop ((names '()))
        (let ((line (read-line in)))
          (if (eof-object? line)
              (reverse names)
              (loop (if (string-prefix? undefined-warning line)
                        (cons (string->symbol
                               (substring line (string-length undefined-warning)
                                          (string-length line)))
                              names)
                        names))))))))

(define undefined-warning "WARNING: reference to undefined variable: ")

(define (mentions? form name)
  (cond ((pair? form) (or (mentions? (car form) name) (mentions? (cdr form) name)))
        ((vector? form) (any (lambda (x) (mentions? x name)) (vector->list form)))
        (else (eq? form name))))

(define (nearest-defined name env)
  (let ((near (nearest-name (symbol->string name)
                            (map symbol->string (visible-names env)))))
    (if near (string-append "; did you mean " near "?") "")))

;;> The names defined in \var{env} and in the environments it imports from.
(define (visible-names env)
  (let loop ((env env) (acc '()))
    (if env (loop (env-parent env) (append (env-exports env) acc)) acc)))

;;> The string of \var{names} nearest \var{text} (two edits, under half), or #f.
(define (nearest-name text names)
  (let ((near (find-nearest-edits text names)))
    (and (pair? near)
         (let ((d (edit-distance text (car near))))
           (and (<= d 2) (< (* 2 d) (string-length text))))
         (car near))))

;;> The lab's code files, as its (code ...) clause names them.
(define (lab-code-files lab)
  (lab-setting lab 'code))

;;> An environment for a person at a REPL: all of Chibi, Murdoch, and
;;> \var{lab-env}'s own procedures, so they travel by name.
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
  (map car (car (read-source file))))

;; Evaluates each form of file in env; an error names the file and line.
(define (load-into file env)
  (for-each (lambda (entry) (at-form-line file entry (lambda () (eval (car entry) env))))
            (car (read-source file))))

;;> (thunk), its error raised again naming \var{file} and \var{entry}'s line.
(define (at-form-line file entry thunk)
  (guard (e ((error-object? e) (error (form-line-text file entry (error-line e)))))
    (thunk)))

(define (form-line-text file entry text)
  (string-append file ":" (number->string (cdr entry)) ": " text))

(define (error-line e)
  (let ((text (error-message e)))
    (if (> (string-length text) 200)
        (string-append (substring text 0 196) " ...")
        text)))

(define (defined-names file)
  (filter-map (lambda (form)
                (and (pair? form) (eq? (car form) 'define) (pair? (cdr form))
                     (if (pair? (cadr form)) (car (cadr form)) (cadr form))))
              (read-forms file)))
