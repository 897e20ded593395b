;;; The lock order (docs/architecture.md): a process started with
;;; MURDOCH_LOCK_ORDER naming a folder reports a lock taken under one of no
;;; lower place, and only then; every mutex of lib/ has a place; and
;;; tests/run has every test's processes check it.
(import (scheme base) (scheme write) (scheme read) (scheme file)
        (srfi 1) (chibi test)
        (only (chibi process) system)
        (only (scheme process-context) get-environment-variable)
        (only (chibi filesystem) directory-files file-directory?)
        (only (murdoch sys wait) lock-ranks)
        (murdoch testing harness))

(define dir (temporary-directory))
(define runs 0)

;; (reports stderr) of a process that runs body, a list of forms with
;; (murdoch sys) and srfi 18 imported, checking into a folder of its own.
(define (checked-run body)
  (set! runs (+ runs 1))
  (let* ((name (string-append dir "/run" (number->string runs)))
         (folder (string-append name ".locks")))
    (system "mkdir" folder)
    (call-with-output-file (string-append name ".scm")
      (lambda (out)
        (write '(import (scheme base) (srfi 18) (murdoch sys)) out)
        (for-each (lambda (form) (write form out) (newline out)) body)))
    (system "sh" "-c" "MURDOCH_LOCK_ORDER=\"$1.locks\" \"$0\" \"$1.scm\" 2>\"$1.err\""
            (tool-path "tools/chibi") name)
    (list (append-map (lambda (f) (read-lines (string-append folder "/" f)))
                      (remove (lambda (f) (member f '("." ".."))) (directory-files folder)))
          (file-text (string-append name ".err")))))

(define running-then-tasks
  '((define running (make-mutex 'running))
    (define tasks (make-mutex 'tasks))))

(test-begin "lock-order")

(test-group "a break of the order is caught, and only a break"
  (let ((r (checked-run (append running-then-tasks
                                '((lock! running) (lock! tasks) (unlock! tasks) (unlock! running))))))
    (test "tasks under running: reported to the folder" '("lock order: took tasks holding running")
          (car r))
    (test-assert "and to standard error" (text-contains? (cadr r) "took tasks holding running")))
  (test "running under tasks, as the order has it: nothing" '()
        (car (checked-run (append running-then-tasks
                                  '((with-lock tasks (lambda () (with-lock running (lambda () #t)))))))))
  (test "with-lock-by is checked as lock! is" '("lock order: took tasks holding running")
        (car (checked-run (append running-then-tasks
                                  '((with-lock running
                                      (lambda ()
                                        (with-lock-by tasks (+ (monotonic-seconds) 1)
                                                      (lambda () 'late) (lambda () 'in)))))))))
  (test "a lock let go is no longer held: running, then tasks, one after the other" '()
        (car (checked-run (append running-then-tasks
                                  '((with-lock running (lambda () #t))
                                    (with-lock tasks (lambda () #t)))))))
  (test "a mailbox waited on, its deadline past, is let go of" '()
        (car (checked-run '((define running (make-mutex 'running))
                            (mailbox-take (make-mailbox) (+ (monotonic-seconds) 0.1)
                                          (lambda () #f))
                            (with-lock running (lambda () #t))))))
  (test "a lock of no place, taken under another, is a break"
        '("lock order: took nameless holding running")
        (car (checked-run '((define running (make-mutex 'running))
                            (with-lock running
                              (lambda () (with-lock (make-mutex 'nameless) (lambda () #t))))))))
  (test "each thread holds its own" '()
        (car (checked-run (append running-then-tasks
                                  '((lock! running)
                                    (thread-join! (thread-start! (make-thread
                                                                  (lambda () (lock! tasks)
                                                                          (unlock! tasks)))))
                                    (unlock! running)))))))

;; What follows each "(make-mutex" of text: the name it is made with, as
;; read, or #f when it is made with none.
(define (mutex-names text)
  (let loop ((from 0) (names '()))
    (let ((at (text-index text "(make-mutex" from)))
      (if (not at)
          (reverse names)
          (let* ((after (+ at (string-length "(make-mutex")))
                 (port (open-input-string (substring text after (string-length text))))
                 (next (read port)))
            (loop after (cons (and (pair? next) (eq? (car next) 'quote) (cadr next))
                              names)))))))

(define (text-index text word from)
  (let ((n (string-length text)) (k (string-length word)))
    (let loop ((i from))
      (cond ((> (+ i k) n) #f)
            ((string=? word (substring text i (+ i k))) i)
            (else (loop (+ i 1)))))))

(test-group "every mutex has a place"
  (let ((made (append-map (lambda (f)
                            (map (lambda (name) (cons name f)) (mutex-names (file-text f))))
                          (files-under (tool-path "lib/murdoch") ".scm"))))
    (test-assert "lib/ makes mutexes" (> (length made) 20))
    (test "each is made with a name that lock-ranks places" '()
          (remove (lambda (m) (assq (car m) lock-ranks)) made))
    (test "docs/architecture.md names each place" '()
          (remove (lambda (rank)
                    (text-contains? (file-text (tool-path "docs/architecture.md"))
                                    (string-append "`" (symbol->string (car rank)) "`")))
                  lock-ranks))))

(test-group "make test checks the order in every process"
  (test-assert "tests/run gives this test a folder for its breaks"
    (let ((folder (get-environment-variable "MURDOCH_LOCK_ORDER")))
      (and folder (file-directory? folder)))))

(test-end)
(test-exit)
