;;; The strict netstring reader: good frames, and each kind of bad one.
(import (scheme base) (scheme read) (scheme write) (chibi test) (chibi io)
        (murdoch wire netstring))

(define (bytes s) (string->utf8 s))
(define (read-all s max)
  (let ((in (open-input-bytevector (bytes s))))
    (let loop ((acc '()))
      (let ((x (read-netstring in max)))
        (if (eof-object? x) (reverse acc) (loop (cons (utf8->string x) acc)))))))
(define (fault s max)
  (guard (e ((netstring-error? e) (netstring-error-message e)))
    (read-all s max)
    'no-fault))
(define (framed s)
  (let ((out (open-output-bytevector)))
    (write-netstring (bytes s) out)
    (utf8->string (get-output-bytevector out))))

(test-begin "netstring")
(test "one frame" '("hello") (read-all "5:hello," 100))
(test "frames back to back" '("a" "" "bc") (read-all "1:a,0:,2:bc," 100))
(test "empty input is no frame" '() (read-all "" 100))
(test "exactly the maximum" '("abcd") (read-all "4:abcd," 4))
(test "writer" "3:abc," (framed "abc"))
(test "a string is framed by its UTF-8 bytes" "5:caf\xe9;,"
  (let ((out (open-output-bytevector)))
    (write-netstring "caf\xe9;" out)
    (utf8->string (get-output-bytevector out))))
(test "round trip of every byte value" 256
  (let* ((bv (let ((b (make-bytevector 256)))
               (do ((i 0 (+ i 1))) ((= i 256) b) (bytevector-u8-set! b i i))))
         (out (open-output-bytevector)))
    (write-netstring bv out)
    (bytevector-length
     (read-netstring (open-input-bytevector (get-output-bytevector out)) 1000))))
(test "garbage" "non-digit byte 71 in length" (fault "GET / HTTP/1.0" 100))
(test "over-long length" "length 101 over 100 bytes" (fault "101:" 100))
(test "too many digits" "length over 100 bytes" (fault "1000000000:a," 100))
(test "leading zero" "leading zero in length" (fault "01:a," 100))
(test "empty length" "empty length" (fault ":a," 100))
(test "truncated length" "truncated length" (fault "12" 100))
(test "truncated payload" "truncated payload" (fault "5:abc" 100))
(test "missing comma" "missing comma after payload" (fault "3:abc;" 100))
(test "missing comma at end" "missing comma after payload" (fault "3:abc" 100))
(test "minus sign" "non-digit byte 45 in length" (fault "-1:" 100))
;; read-netstring takes a frame that its port's buffer holds whole in one
;; C call, and reads anything else byte by byte.  A port that hands over a
;; byte at a time never holds a whole frame, so it is read byte by byte;
;; the two must agree on every input, frames and faults alike.
(define (trickle bytes)
  (let ((i 0))
    (make-custom-binary-input-port
     (lambda (buf start end)            ; answers the new end of buf
       (if (>= i (bytevector-length bytes))
           start
           (begin (bytevector-u8-set! buf start (bytevector-u8-ref bytes i))
                  (set! i (+ i 1))
                  (+ start 1)))))))

;; The payloads read before the end or the first fault, and the fault.
(define (outcome in max)
  (let loop ((acc '()))
    (let ((x (guard (e ((netstring-error? e) (netstring-error-message e)))
               (read-netstring in max))))
      (cond ((bytevector? x) (loop (cons x acc)))
            ((eof-object? x) (list (reverse acc) 'end))
            (else (list (reverse acc) x))))))

;; Inputs made mostly of the pieces netstrings are made of, from a fixed
;; seed: the same inputs every run.
(define seed 12345)
(define (random-below n)
  (set! seed (modulo (+ (* seed 1103515245) 12345) 2147483648))
  (modulo (quotient seed 65536) n))
(define pieces
  '#("0" "1" "2" "3" "9" "10" "12" ":" "," "a" "bc" "3:abc," "0:," "01:" "-"))
(define (random-input)
  (let loop ((k (random-below 8)) (acc ""))
    (if (zero? k)
        (string->utf8 acc)
        (loop (- k 1)
              (string-append acc (vector-ref pieces
                                             (random-below (vector-length pieces))))))))

(test "the whole-frame and the byte-wise reader agree on 3000 inputs" '()
  (let loop ((i 0) (disagreements '()))
    (if (= i 3000)
        disagreements
        (let ((input (random-input)))
          (loop (+ i 1)
                (if (equal? (outcome (open-input-bytevector input) 10)
                            (outcome (trickle input) 10))
                    disagreements
                    (cons (utf8->string input) disagreements)))))))

;; plain-message reads what our writer writes, in C, as read would; on
;; anything else it answers its last argument, and read takes over.
(define other (list 'other))
(define (plain text) (plain-message text 100 other))
(define (read-whole text)
  (guard (e (#t 'unreadable))
    (let* ((in (open-input-string text)) (x (read in)))
      (if (eof-object? (peek-char in)) x 'trailing))))
(define (written x)
  (let ((out (open-output-string))) (write-simple x out) (get-output-string out)))
;; The texts plain-message read that read reads otherwise.
(define (misread texts)
  (filter-texts (lambda (t) (let ((x (plain t)))
                              (and (not (eq? x other)) (not (equal? x (read-whole t))))))
                texts))
(define (filter-texts keep? texts)
  (cond ((null? texts) '())
        ((keep? (car texts)) (cons (car texts) (filter-texts keep? (cdr texts))))
        (else (filter-texts keep? (cdr texts)))))

(test "a request's call"
  '(apply 17 #(murdoch:global receive-request)
          (all w1 #(murdoch:closure (lambda () #t) ((x . -12) (s . "a\"b\nc"))) ()))
  (plain "(apply 17 #(murdoch:global receive-request) (all w1 #(murdoch:closure (lambda () #t) ((x . -12) (s . \"a\\\"b\\nc\"))) ()))"))
(test "what is not plain is left to read"
  (make-list 22 #t)
  (map (lambda (t) (eq? other (plain t)))
       '("0.5" "1/2" "+i" "-inf.0" ".5" "..." "#\\a" "'a" "(a ;c\n)" "|a b|"
         "#u8(1)" "#0=(a . #0#)" "\"\\x41;\"" "caf\xe9;" "(1 2" "" "x y" " x " "#(1 . 2)"
         "123456789012345678" "abc#t" "\"a\\\x0;b\"")))
(test "nesting up to the limit, and not past it" '(#t #t)
  (let ((nest (lambda (n) (string-append (make-string n #\() "x" (make-string n #\))))))
    (list (pair? (plain (nest 100))) (eq? other (plain (nest 101))))))
(test "fixed texts are read as read reads them" '()
  (misread '("()" "#()" "(a . b)" "(a . (b c))" "(a . b c)" "(. a)" "(a .b)" "+" "-"
             "007" "-0" "+5" "12345678901234567" "#t" "#f" "#true" "mobile.in_use" "->x"
             "(#t#f)" "(\"a\"b)" "(\r\n a\t)" "  x" "a.b.c" "[a]" "{a}")))
;; Values of every kind the wire carries, from the fixed seed.
(define (random-value depth)
  (case (random-below (if (> depth 4) 6 9))
    ((0) (- (random-below 2000000) 1000000))
    ((1) (vector-ref '#(a b mobile.in_use murdoch:closure lambda + - ! $x <=? |\x3bb;|)
                     (random-below 11)))
    ((2) (vector-ref '#("" "a b" "q\"uote" "back\\slash" "nl\nx" "tab\tx" "\xe9;" "ctl\x1;")
                     (random-below 8)))
    ((3) (zero? (random-below 2)))
    ((4) (vector-ref '#(0.5 -1.25 1e100 1/3 #\a) (random-below 5)))
    ((5) '())
    ((6) (random-list (random-below 5) depth))
    ((7) (cons (random-value (+ depth 1)) (random-value (+ depth 1))))
    (else (list->vector (random-list (random-below 4) depth)))))
(define (random-list n depth)
  (if (zero? n) '() (cons (random-value (+ depth 1)) (random-list (- n 1) depth))))
(test "2000 written values are read as read reads them" '()
  (misread (let loop ((i 0) (acc '()))
             (if (= i 2000) acc (loop (+ i 1) (cons (written (random-value 0)) acc))))))

(test-end)
(test-exit)
