;;;; Sendable procedures: closures that travel as S-expressions.
;;
;; Chibi keeps no source for a compiled lambda, so Murdoch's `lambda`
;; does: its closure carries a `sendable-info` with the source and a thunk
;; that answers the local variables the body mentions.  Globals are looked
;; up by name where the closure lands, as the thesis's var-ref relies on.
;; A value travels written with `write`; data stands for itself, and what
;; `read` cannot rebuild is a tagged vector:
;;   #(murdoch:global NAME)             a procedure bound to NAME where it lands
;;   #(murdoch:closure SOURCE ((NAME . VALUE) ...))
;;   #(murdoch:proxy UID ID)            a procedure made by encap
;;   #(murdoch:made NAME ARG ...)       what (NAME ARG ...) made (made-by!)
;;   #(murdoch:vector ELEMENT ...)      a vector, so a user's is never a tag
;;   #(murdoch:void) #(murdoch:eof)
;; Anything else (a port, a record) stops at the sender, naming what held it.

(define-lean-record-type sendable-info
  (make-sendable-info source+names values)
  sendable-info?
  (source+names sendable-info-source+names)
  (values sendable-info-values))

(define-record-type proxy-ref
  (make-proxy-ref uid id)
  proxy-ref?
  (uid proxy-ref-uid)
  (id proxy-ref-id))

;;> Raised when a value cannot travel, naming what held it.
(define (send-fail . parts)
  (raise (make-exception 'send-error (apply string-append parts) '() #f #f)))

(define (send-error? e)
  (and (exception? e) (eq? (exception-kind e) 'send-error)))

;;; The lambda that keeps its source

;; Every symbol of the body outside quote: a superset of its variables.
(define (body-symbols body)
  (let walk ((x body) (acc '()))
    (cond
     ((pair? x)
      (if (and (eq? (car x) 'quote) (pair? (cdr x)))
          acc
          (walk (cdr x) (walk (car x) acc))))
     ((or (symbol? x) (syntactic-closure? x))
      (if (memq x acc) acc (cons x acc)))
     (else acc))))

;; Local when the expander's innermost binding is a lambda's parameter.
(define (local-variable? id env)
  (let ((cell (env-cell env id)))
    (and cell (lambda? (cdr cell)))))

(define (expand-sendable-lambda expr use-env mac-env)
  (let* ((formals (cadr expr))
         (body (cddr expr))
         (locals (filter (lambda (id) (local-variable? id use-env))
                         (body-symbols body)))
         (r (lambda (name) (make-syntactic-closure mac-env '() name)))
         (info (r 'info)))
    ;; The user's formals and body mean what they mean where it is written.
    `(,(r 'let) ((,info (,(r 'make-sendable-info)
                         (,(r 'quote)
                          ,(cons `(lambda ,@(strip-syntactic-closures (cdr expr)))
                                 (map strip-syntactic-closures locals)))
                         (,(r '%lambda) () (,(r 'list) ,@locals)))))
       (,(r '%lambda) ,formals
        ;; The test keeps `info' among the closure's variables, where
        ;; closure-info finds it; Chibi drops a reference with no use.
        (,(r 'if) ,info (,(r 'let) () ,@body) #f)))))

;;> Murdoch's \scheme{lambda}: an ordinary lambda whose closures can travel.
(define-syntax sendable-lambda
  (lambda (expr use-env mac-env)
    (expand-sendable-lambda expr use-env mac-env)))

;;> Murdoch's \scheme{define}: as usual, a procedure made by the sendable lambda.
(define-syntax sendable-define
  (er-macro-transformer
   (lambda (expr rename compare)
     (let ((target (cadr expr)))
       (if (pair? target)
           `(,(rename '%define) ,(car target)
             (,(rename 'name-procedure)
              (,(rename 'sendable-lambda) ,(cdr target) ,@(cddr expr))
              ',(car target)))
           `(,(rename '%define) ,@(cdr expr)))))))

(define (name-procedure proc name)
  (procedure-name-set! proc name)
  proc)

(define (closure-var proc pred)
  (var-from (procedure-vars proc) pred 0))

;; No named let, whose closure each look would make (docs/speed.md).
(define (var-from vars pred i)
  (cond ((= i (vector-length vars)) #f)
        ((pred (vector-ref vars i)) (vector-ref vars i))
        (else (var-from vars pred (+ i 1)))))

(define (closure-info proc) (closure-var proc sendable-info?))

;;> True when \var{proc} carries its source.
(define (sendable-procedure? proc)
  (and (procedure? proc) (not (opcode? proc)) (closure-info proc) #t))

;;; Proxies

;; A proxy is a closure of this one lambda, recognised by its code.
(define (make-proxy-procedure ref call)
  (lambda args (call ref args)))

(define proxy-code
  (procedure-code (make-proxy-procedure #f #f)))

(define (proxy-procedure-ref proc)
  (and (procedure? proc)
       (not (opcode? proc))
       (eq? (procedure-code proc) proxy-code)
       (closure-var proc proxy-ref?)))

;;; Encoding

(define (global-name proc env)
  (let ((name (if (opcode? proc)
                  (string->symbol (opcode-name proc))
                  (procedure-name proc))))
    (and (symbol? name)
         (let ((cell (env-cell env name)))
           (and cell (eq? (cdr cell) proc)))
         name)))

(define (tag? x)
  (and (vector? x) (> (vector-length x) 0)
       (memq (vector-ref x 0) '(murdoch:global murdoch:closure murdoch:proxy
                               murdoch:made murdoch:vector murdoch:void murdoch:eof))))

(define void-value (if #f #f))

(define (describe x)
  (cond ((input-port? x) "an input port")
        ((output-port? x) "an output port")
        ((thread? x) "a thread")
        ((mutex? x) "a mutex")
        ((condition-variable? x) "a condition variable")
        ((procedure? x) "a procedure made without Murdoch's lambda")
        (else (string-append "a " (symbol->string (type-name (type-of x)))))))

;; What held a value, for an error; a thunk makes it only when needed.
(define (what-string what) (if (procedure? what) (what) what))

;;; Limits
;; A value from another address space is input.  Deep nesting would
;; outgrow Chibi's stack, which ends the process, and long or circular
;; lists do too when walked by recursion: so walks go down cdrs by
;; iteration counting depth, and encoding counts pairs, up to a frame's.
;; (Chibi's writer cuts what nests past 10,000: max-depth stays below.)

;; The limits of the lab this process joined, read by set-value-limits!.
(define-record-type value-limits
  (make-value-limits depth pairs)
  value-limits?
  (depth limits-depth)                  ; the lab's max-depth
  (pairs limits-pairs))                 ; a frame of max-frame bytes holds fewer

;; The node's limits part: every value the process sends or receives is its lab's.
(define-syntax the-limits (syntax-rules () ((_) (node-limits *node*))))

;;> Takes the value limits of this process's lab: max-depth, and max-frame / 2 pairs.
(define (set-value-limits!)
  (node-limits-set! (this-node)
                    (make-value-limits (setting 'max-depth)
                                       (quotient (setting 'max-frame) 2))))

;; A macro, run on every level of every value (docs/speed.md).
(define-syntax check-depth
  (syntax-rules ()
    ((_ depth what) (if (> depth (limits-depth (the-limits))) (too-deep what)))))

(define (too-deep what)
  (send-fail (what-string what) " nests deeper than the lab's max-depth, "
             (number->string (limits-depth (the-limits)))))

;; (map f ls) by iteration, ls maybe improper: f gets its tail too.
(define (map-elements f ls)
  (let loop ((x ls) (acc '()))
    (if (pair? x)
        (loop (cdr x) (cons (f (car x)) acc))
        (append-reverse! acc (if (null? x) '() (f x))))))

(define (append-reverse! rev tail)
  (if (null? rev)
      tail
      (let ((next (cdr rev)))
        (set-cdr! rev tail)
        (append-reverse! next rev))))

;; True of data that stands for itself, left uncopied (docs/speed.md);
;; plain-within? (plain.c) gives up at a budget of pairs or the depth limit.
(define (plain? x) (plain-within? x 100000 (limits-depth (the-limits))))

;;> The S-expression that stands for \var{x} on the wire: \var{env}'s
;;> procedures travel by name; \var{what} names \var{x} in errors.
(define (encode x env what)
  (cond ((plain? x) x)
        ((and (procedure? x) (known-encoding x env)))
        (else (encode-compound x env what))))

;; Defined at the top (docs/speed.md); left is a vector of the pairs yet allowed.
(define (encode-compound x env what)
  (enc x env what 0 (make-vector 1 (limits-pairs (the-limits)))))

(define (spend! left n what)
  (vector-set! left 0 (- (vector-ref left 0) n))
  (if (negative? (vector-ref left 0))
      (send-fail "cannot send " (what-string what)
                 ": it is larger than a frame holds, or circular")))

(define (enc x env what depth left)
  (cond
   ((plain-atom? x) x)
   ((pair? x) (check-depth (+ depth 1) what)
              (map-elements (lambda (e)
                              (spend! left 1 what)
                              (enc e env what (+ depth 1) left))
                            x))
   ((vector? x)
    (check-depth (+ depth 1) what)
    (spend! left (vector-length x) what)
    (list->vector
     (cons 'murdoch:vector
           (map-elements (lambda (e) (enc e env what (+ depth 1) left))
                         (vector->list x)))))
   ((eof-object? x) (vector 'murdoch:eof))
   ((eq? x void-value) (vector 'murdoch:void))
   ((procedure? x) (enc-procedure x env what depth left))
   (else (send-fail "cannot send " (what-string what) ": it is "
                    (describe x)))))

(define (enc-procedure p env what depth left)
  (cond
   ((proxy-procedure-ref p)
    => (lambda (ref) (vector 'murdoch:proxy (proxy-ref-uid ref)
                             (proxy-ref-id ref))))
   ((global-name p env)
    => (lambda (name)
         (know-encoding! p env (env-cell env name)
                         (vector 'murdoch:global name))))
   ((hash-table-ref/default *made* p #f)
    => (lambda (recipe)
         (list->vector
          (cons 'murdoch:made
                (cons (car recipe)
                      (map-elements (lambda (e) (enc e env what (+ depth 1) left))
                                    (cdr recipe)))))))
   ((and (not (opcode? p)) (closure-info p))
    => (lambda (info)
         (let ((code (enc-closure info env depth left))
               (source (info-capture-free-source info)))
           (if source (know-encoding! source env #f code) code))))
   (else (send-fail "cannot send " (what-string what) ": it is "
                    (describe p)))))

;;> Answers \var{proc}, which \scheme{(name arg ...)} made: it travels as
;;> that call, \var{name} bound to the same maker where it lands.
(define (made-by! proc name . args)
  (if (>= (hash-table-size *made*) max-known)
      (set! *made* (make-hash-table eq?)))
  (hash-table-set! *made* proc (cons name args))
  proc)

;; Global: a procedure's maker is the same for every thread.
(define *made* (make-hash-table eq?))   ; procedure -> (NAME ARG ...)

;; Global, a cache for every thread: encodings of procedures that do not
;; change, a global's by name while bound, a capture-free closure's by its
;; source (docs/speed.md); max-known of them, so new globals are let go.
(define max-known 512)
(define *known* (make-hash-table eq?))  ; procedure or source -> (env cell . code)

;; hash-table-cell, and no let (docs/speed.md).
(define (known-encoding p env)
  (known-else-source (known-code (hash-table-cell *known* p #f) p env) p env))

;; No or, whose let makes a closure: one an encoding.
(define (known-else-source code p env)
  (if code code (known-source-code (capture-free-source p) env)))

(define (known-source-code source env)
  (and source (known-code (hash-table-cell *known* source #f) #f env)))

;; The code of entry, (key . (env cell . code)), if still p's in env.
(define (known-code entry p env)
  (and entry
       (eq? (cadr entry) env)
       (if (car (cddr entry)) (eq? (cdr (car (cddr entry))) p) #t)
       (cdr (cddr entry))))

;; The source and names of p, a closure that captures no variable, or #f.
(define (capture-free-source p)
  (and (not (opcode? p)) (info-capture-free-source (closure-info p))))

(define (info-capture-free-source info)
  (and info
       (null? (cdr (sendable-info-source+names info)))
       (sendable-info-source+names info)))

(define (know-encoding! key env cell code)
  (if (>= (hash-table-size *known*) max-known)
      (set! *known* (make-hash-table eq?)))
  (hash-table-set! *known* key (cons env (cons cell code)))
  code)

;; A captured value is written three levels down.
(define (enc-closure info env depth left)
  (let ((source+names (sendable-info-source+names info)))
    (vector 'murdoch:closure (car source+names)
            (enc-bindings (car source+names) (cdr source+names)
                          ((sendable-info-values info)) env (+ depth 3) left))))

(define (enc-bindings source names values env depth left)
  (if (null? names)
      '()
      (cons (cons (car names)
                  (enc (car values) env
                       (lambda ()
                         (string-append "variable " (symbol->string (car names))
                                        " of " (abridged source 60)))
                       depth left))
            (enc-bindings source (cdr names) (cdr values) env depth left))))

;;> \var{x} as \scheme{write} writes it, cut to \var{width} characters with "...".
(define (abridged x width)
  (let ((s (let ((out (open-output-string)))
             (write x out)
             (get-output-string out))))
    (if (> (string-length s) width)
        (string-append (substring s 0 (- width 3)) "...")
        s)))

;;; Decoding

;; Makers kept by source, as compiling is decoding's dear part; emptied at
;; max-makers, as a peer could send sources without end (docs/speed.md).
(define max-makers 4096)
(define max-cells 64)

(define-syntax closure-or-opcode?
  (syntax-rules () ((_ x) (if (closure? x) #t (opcode? x)))))

;; The procedure in cell, the env-cell of global name (no let: see known-encoding).
(define (procedure-in cell name)
  (if (and cell (closure-or-opcode? (cdr cell)))
      (cdr cell)
      (error "no procedure of this name here" name)))

;; A closure that captures nothing is made once, and comes as that one.
(define (kept-maker maker key)
  (if (null? (cdr key))
      (let ((proc (maker))) (lambda () proc))
      maker))

(define (make-closure-compiler env)
  (let ((makers (make-hash-table chibi-equal?)))
    ;; See known-encoding.
    (define (maker entry key)
      (if entry (cdr entry) (compile! key)))
    (define (compile! key)
      (let ((maker (kept-maker (eval `(lambda ,(cdr key) ,(car key)) env) key)))
        (if (>= (hash-table-size makers) max-makers)
            (set! makers (make-hash-table chibi-equal?)))
        (hash-table-set! makers key maker)
        maker))
    (define (maker-of key) (maker (hash-table-cell makers key #f) key))
    (lambda (source names) (maker-of (cons source names)))))

;;> Returns a procedure that rebuilds values encoded by \scheme{encode},
;;> resolving globals and sources in \var{env} and proxies by \var{proxy};
;;> in place, so the value must be fresh from a frame.
(define (make-decoder env proxy)
  (let ((compile (make-closure-compiler env))
        (cells '()))                    ; (NAME . CELL): the lab's code defines all before a call
    (define (dec x depth)
      (cond
       ((pair? x) (fill-places! (tagged-places x depth (limits-depth (the-limits))))
                  x)
       ((vector? x) (dec-tagged x depth))
       (else x)))
    ;; The walk down the pairs is C's (plain.c); its places, here, each
    ;; a pair and (+ (* 2 depth) 1) for its car, (* 2 depth) for its cdr.
    (define (fill-places! places)
      (cond ((vector? places) (fill-from! places 0))
            ((eq? places 'too-deep) (too-deep "a received value"))))
    (define (fill-from! places i)
      (if (< i (vector-length places))
          (begin (fill-place! (vector-ref places i) (vector-ref places (+ i 1)))
                 (fill-from! places (+ i 2)))))
    (define (fill-place! p code)
      (if (eq? 1 (remainder code 2))   ; odd? is a call
          (set-car! p (dec-tagged (car p) (quotient code 2)))
          (set-cdr! p (dec-tagged (cdr p) (quotient code 2)))))
    (define (dec-tagged v depth)
      (check-depth (+ depth 1) "a received value")
      (dec-tag (vector-ref v 0) v depth))
    (define (dec-tag tag v depth)
      (cond
       ((eq? tag 'murdoch:closure)
        (if (null? (vector-ref v 2))      ; the common case, made cheap
            ((compile (vector-ref v 1) '()))
            (apply (compile (vector-ref v 1) (map car (vector-ref v 2)))
                   (map (lambda (b) (dec (cdr b) (+ depth 1)))
                        (vector-ref v 2)))))
       ((eq? tag 'murdoch:global) (global-ref (vector-ref v 1)))
       ((eq? tag 'murdoch:made)
        (let ((recipe (dec (cdr (vector->list v)) depth)))
          (apply made-by! (apply (global-ref (car recipe)) (cdr recipe)) recipe)))
       ((eq? tag 'murdoch:vector)
        (list->vector (dec (cdr (vector->list v)) depth)))
       ((eq? tag 'murdoch:proxy) (proxy (vector-ref v 1) (vector-ref v 2)))
       ((eq? tag 'murdoch:void) void-value)
       ((eq? tag 'murdoch:eof) (eof-object))
       (else (error "unknown tag in a received value" v))))
    (define (global-ref name) (procedure-in (cell-of name (assq name cells)) name))
    (define (cell-of name entry)
      (if entry (cdr entry) (new-cell! name (env-cell env name))))
    (define (new-cell! name cell)
      (if cell
          (set! cells (cons (cons name cell) (if (< (length cells) max-cells) cells '()))))
      cell)
    (lambda (x) (dec x 0))))
