;;;; Records made without a closure (Chibi's constructor makes one each
;;;; time: docs/speed.md): made bare by Chibi's own maker, their fields
;;;; filled by their places in a procedure of their own.

;;> R7RS's define-record-type: the same records, made without a closure.
(define-syntax define-lean-record-type
  (er-macro-transformer
   (lambda (expr rename compare)
     (let ((name (cadr expr))
           (constructor (car (cddr expr)))
           (fields (cdr (cdr (cddr expr)))))
       (if (not (and (identifier? name) (pair? constructor)))
           (error "define-lean-record-type: a name and (constructor field ...)" expr))
       (let ((bare (record-helper "%bare-" name))
             (fill (record-helper "%fill-" name))
             (_define (rename 'define)))
         `(,(rename 'begin)
           (,(rename 'chibi-define-record-type) ,name (,(record-helper "%let-" name))
            ,@(cdr (cddr expr)))
           (,_define ,bare (,(rename 'make-constructor)
                            ,(symbol->string (identifier->symbol (car constructor)))
                            ,name))
           (,_define ,constructor (,fill (,bare) ,@(cdr constructor)))
           (,_define (,fill record ,@(cdr constructor))
                     ,@(map (lambda (field)
                              `(,(rename 'slot-set!) ,name record
                                ,(field-place field fields) ,field))
                            (cdr constructor))
                     record)))))))

(define (record-helper prefix name)
  (string->symbol (string-append prefix (symbol->string (identifier->symbol name)))))

;; Chibi keeps a record's fields in the order they are declared.
(define (field-place field fields)
  (let loop ((specs fields) (i 0))
    (cond ((null? specs) (error "define-lean-record-type: no such field" field))
          ((eq? (identifier->symbol (car (car specs))) (identifier->symbol field)) i)
          (else (loop (cdr specs) (+ i 1))))))
