;;;; Reading a Scheme file with the lines of its lists, part of (murdoch
;;;; lab), and errors that name the file, the line and the clause.

;; The lines where the lists of the file being read start, ((LIST . LINE)
;; ...) by eq?, for its errors: a parameter, as each read binds its own.
(define clause-lines (make-parameter '()))

(define (clause-line c)
  (cond ((assq c (clause-lines)) => cdr) (else #f)))

;; An error naming the file, the line of clause c, c on one line, and why.
(define (lab-file-error path c why)
  (let ((line (clause-line c)))
    (error (string-append path (if line (string-append ":" (number->string line)) "")
                          ": " (clause-text c) ": " why))))

;; c as written, on one line, cut at 60 characters.
(define (clause-text c)
  (let* ((out (open-output-string))
         (text (begin (write c out) (get-output-string out))))
    (if (> (string-length text) 60)
        (string-append (substring text 0 56) " ...")
        text)))

(define (line-words c)
  (cond ((clause-line c) => (lambda (n) (string-append " on line " (number->string n))))
        (else "")))

;;> The data of the Scheme file at \var{path} and their lines: (((DATUM .
;;> LINE) ...) (LIST . LINE) ...), lists by eq?.  A list left open is named
;;> as the first whose column a later line starts at or left of, else the
;;> innermost.
(define (read-source path)
  (let ((in (guard (e ((file-error? e)
                        (error (string-append "cannot read " path
                                              ": couldn't open input file"))))
              (open-input-file path))))
    (let ((source (read-source-port path in)))
      (close-input-port in)
      source)))

(define (read-source-port path in)
  (let ((lines '())
        (column 0)                      ; of the next datum, when it starts a line
        (fresh-line? #t)
        (suspect #f))                   ; (LINE COLUMN) of a list that looks open
    (define (skip!)
      (let ((c (peek-char in)))
        (cond ((eof-object? c))
              ((char=? c #\newline)
               (read-char in) (set! column 0) (set! fresh-line? #t) (skip!))
              ((char-whitespace? c) (read-char in) (set! column (+ column 1)) (skip!))
              ((char=? c #\;)
               (read-line in) (set! column 0) (set! fresh-line? #t) (skip!)))))
    (define (fail line why)
      (error (string-append path ":" (number->string line) ": " why)))
    ;; The next datum; open: ((LINE COLUMN) ...) of the lists it is in,
    ;; innermost first, COLUMN #f for one that did not start its line.
    (define (datum open)
      (skip!)
      (let ((line (port-line in))
            (col (and fresh-line? column))
            (c (peek-char in)))
        (set! fresh-line? #f)
        (if (and col (not suspect))
            (set! suspect (find (lambda (o)
                                  (and (cadr o) (< (car o) line) (<= col (cadr o))))
                                (reverse open))))
        (cond
         ((eof-object? c) c)
         ((char=? c #\() (read-char in) (read-list line (cons (list line col) open)))
         ((char=? c #\)) (read-char in) (fail line "a ) that closes nothing"))
         (else
          (guard (e (#t (fail line (string-append "cannot read this: "
                                                  (condition-message e)))))
            (read in))))))
    (define (read-list line open)
      (let loop ((items '()))
        (skip!)
        (let ((next (peek-char in)))
          (cond
           ((eof-object? next)
            (fail (car (or suspect (car open)))
                  "this list has no closing ): the file ends inside it"))
           ((char=? next #\)) (read-char in)
            (let ((form (reverse items)))
              (set! lines (cons (cons form line) lines))
              form))
           ((char=? next #\.) (read-char in)
            (if (delimiter? (peek-char in))
                (let ((tail (datum open)))
                  (skip!)
                  (if (not (eqv? (peek-char in) #\)))
                      (fail line "a dotted list ends after one datum"))
                  (read-char in)
                  (let ((form (append-reverse items tail)))
                    (set! lines (cons (cons form line) lines))
                    form))
                (loop (cons (dotted-token in) items))))
           (else (loop (cons (datum open) items)))))))
    (let loop ((data '()))
      (skip!)
      (let* ((line (port-line in))
             (d (datum '())))
        (if (eof-object? d)
            (cons (reverse data) lines)
            (loop (cons (cons d line) data)))))))

(define (delimiter? c)
  (or (eof-object? c) (char-whitespace? c) (memv c '(#\( #\) #\" #\;))))

;; A number or symbol that starts with the . already read, as .5 or ...
(define (dotted-token in)
  (let loop ((chars '(#\.)))
    (if (delimiter? (peek-char in))
        (let ((text (list->string (reverse chars))))
          (or (string->number text) (string->symbol text)))
        (loop (cons (read-char in) chars)))))
