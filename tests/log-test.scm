;;; (murdoch sys log): one line a message, whole, whichever threads log at
;;; once.  A line written in pieces was cut into by another thread's: an
;;; address space's "listening on" came out inside a warning, and the lab
;;; script, which waits for that line, stopped the lab.
(import (scheme base) (scheme write) (srfi 1) (srfi 18) (chibi test)
        (chibi string) (murdoch sys))

(set-log-name! "murdoch t")
(stamp-log-lines!)

;; The lines that threads logging at once wrote to one port.
(define (logged-at-once threads lines)
  (let ((out (open-output-string)))
    (for-each thread-join!
              (map (lambda (t)
                     (thread-start!
                      (make-thread
                       (lambda ()
                         (parameterize ((current-error-port out))
                           (do ((i 0 (+ i 1))) ((= i lines))
                             (log-warn "thread " t " line " i ": "
                                       (make-string 40 #\x) " " (list t i))))))))
                   (iota threads)))
    (let ((text (get-output-string out)))
      (string-split text #\newline))))

;; A whole line: the stamp, the name, the level and the parts, once each.
(define (whole? line)
  (and (= (length (string-split line #\:)) 6)   ; the stamp has two colons
       (string-prefix? "murdoch t: warning: thread "
                       (substring line 25 (string-length line)))
       (string-suffix? ")" line)))

(test-begin "log")
(let ((lines (remove string-null? (logged-at-once 4 300))))
  (test "every line logged by four threads at once is there" 1200 (length lines))
  (test "and whole" 0 (count (lambda (line) (not (whole? line))) lines)))
(test "a line is stamped with the time, named and levelled"
    "murdoch t: note 1"
  (let ((out (open-output-string)))
    (parameterize ((current-error-port out)) (log-note "note " 1))
    (let ((line (get-output-string out)))
      (substring line 25 (- (string-length line) 1)))))
(test-end)
(test-exit)
