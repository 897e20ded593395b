;;; Replays every tests/transcripts/*.txt against a fresh lab of its own
;;; (docs/transcripts.md): `bin/murdoch lab` on a free port base, then
;;; `bin/murdoch repl` with the transcript's input piped in.
;;; tests/run: long
(import (scheme base) (srfi 1) (chibi test) (only (chibi string) string-suffix?)
        (only (chibi filesystem) directory-files open-pipe
              open-input-file-descriptor open-output-file-descriptor)
        (murdoch testing harness) (murdoch testing transcript))

(define (transcript-files)
  (let ((dir (tool-path "tests/transcripts")))
    (map (lambda (f) (string-append dir "/" f))
         (sort-strings (filter (lambda (f) (string-suffix? ".txt" f))
                               (directory-files dir))))))

(define (sort-strings ls)
  (if (null? ls)
      '()
      (let ((pivot (car ls)))
        (append (sort-strings (filter (lambda (s) (string<? s pivot)) (cdr ls)))
                (list pivot)
                (sort-strings (remove (lambda (s) (string<? s pivot)) (cdr ls)))))))

(test-begin "transcripts")
;; A REPL killed at its time limit leaves the pipe that types its input
;; with no reader: writing to it must not end this test without a word.
(test "writing to a REPL that has gone leaves this test running" 'carried-on
  (let* ((pipe (open-pipe))
         (out (open-output-file-descriptor (cadr pipe))))
    (close-port (open-input-file-descriptor (car pipe)))
    (guard (e (#t 'carried-on))
      (write-string "(+ 1 2)\n" out)
      (flush-output-port out)
      'carried-on)))
(for-each (lambda (file) (check-transcript file (read-transcript file)))
          (transcript-files))
(test-end)
(test-exit)
