;;; docs/thesis-map.md: each name of the thesis's appendix that the map
;;; gives a file is defined in that file, and each it gives none says why.
(import (scheme base) (scheme write) (scheme char) (scheme cxr) (srfi 1) (chibi test)
        (murdoch testing harness))

;; The cells of a table row "| a | b | ... |", trimmed.
(define (row-cells line)
  (let loop ((chars (string->list line)) (cell '()) (cells '()))
    (cond ((null? chars) (reverse cells))
          ((char=? (car chars) #\|)
           (loop (cdr chars) '() (cons (trim (list->string (reverse cell))) cells)))
          (else (loop (cdr chars) (cons (car chars) cell) cells)))))

(define (trim s)
  (let* ((cs (string->list s))
         (strip (lambda (cs) (drop-while char-whitespace? cs))))
    (list->string (reverse (strip (reverse (strip cs)))))))

(define (unquote-code s)
  (if (and (> (string-length s) 1) (char=? (string-ref s 0) #\`))
      (substring s 1 (- (string-length s) 1))
      s))

;; (appendix name file-or-#f note) for each row of the map's table.
(define entries
  (filter-map (lambda (line)
                (let ((cells (row-cells line)))
                  (and (= (length cells) 5)
                       (text-contains? (list-ref cells 1) ".scm")
                       (list (list-ref cells 1)
                             (unquote-code (list-ref cells 2))
                             (let ((here (list-ref cells 3)))
                               (and (not (string=? here "—")) (unquote-code here)))
                             (list-ref cells 4)))))
              (read-lines (tool-path "docs/thesis-map.md"))))

;; Whether file defines name: (define (name, (define name or
;; (define-syntax name, followed by a space, a paren or the line's end.
(define (defines? file name)
  (any (lambda (line)
         (any (lambda (head)
                (let ((start (string-append head name)))
                  (or (string=? line start)
                      (text-contains? line (string-append start " "))
                      (text-contains? line (string-append start ")")))))
              '("(define (" "(define " "(define-syntax ")))
       (read-lines (tool-path file))))

(test-begin "thesis-map")

(test "the map lists the appendix's names" #t (> (length entries) 60))

(test "each name given a file is defined there" '()
  (filter-map (lambda (e)
                (and (caddr e) (not (defines? (caddr e) (cadr e)))
                     (list (cadr e) (caddr e))))
              entries))

(test "each name given none says why" '()
  (filter-map (lambda (e)
                (and (not (caddr e)) (string=? (cadddr e) "") (cadr e)))
              entries))

(test-end)
(test-exit)
