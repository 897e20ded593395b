;;; docs/reference.md is what tools/gen-reference.scm writes from the
;;; ;;> comments, and every export of (murdoch) has a comment: a new export
;;; without one fails here.
(import (scheme base) (scheme write) (scheme read) (scheme file) (srfi 1) (chibi test)
        (only (chibi process) system?)
        (murdoch testing harness))

(define dir (temporary-directory))
(define generated (string-append dir "/reference.md"))

(system? "sh" "-c" "cd \"$0\" && tools/chibi tools/gen-reference.scm >\"$1\""
         (tool-path ".") generated)

;; The name each row of the tables is about: its first cell, `NAME` or
;; `(NAME ARG ...)`.
(define (row-names text)
  (filter-map (lambda (line)
                (and (> (string-length line) 3) (string=? "| `" (substring line 0 3))
                     (let* ((cell (string-copy line 3))
                            (cell (if (char=? (string-ref cell 0) #\()
                                      (string-copy cell 1)
                                      cell))
                            (end (let loop ((i 0))
                                   (if (memv (string-ref cell i) '(#\space #\) #\`))
                                       i
                                       (loop (+ i 1))))))
                       (string->symbol (substring cell 0 end)))))
              (text-lines text)))

;; The names whose row says they have no comment.
(define (undocumented text)
  (row-names (apply string-append
                    (map (lambda (line) (string-append line "\n"))
                         (filter (lambda (line)
                                   (text-contains? line "(no `;;>` comment yet)"))
                                 (text-lines text))))))

(test-begin "reference")

(test "the generator writes a page" #t
  (text-contains? (file-text generated) "# Reference: the (murdoch) library"))

(test (string-append "docs/reference.md is up to date"
                     " (tools/chibi tools/gen-reference.scm > docs/reference.md)")
    #t
  (string=? (file-text generated) (file-text (tool-path "docs/reference.md"))))

(test "every export has a ;;> comment" '()
  (undocumented (file-text generated)))

(test "each export of lib/murdoch.sld has its row" '()
  (let ((rows (row-names (file-text generated))))
    (remove (lambda (name) (memq name rows))
            (map (lambda (e) (if (pair? e) (car (cddr e)) e))
                 (cdr (assq 'export
                            (cddr (call-with-input-file (tool-path "lib/murdoch.sld")
                                    read))))))))

(test-end)
(system? "rm" "-rf" dir)
(test-exit)
