;;; HMAC-SHA256 against the test vectors of RFC 4231, section 4.
(import (scheme base) (chibi test) (murdoch hmac))

(define (repeat byte n) (make-bytevector n byte))
(define (hex->bytevector hex)
  (let ((bv (make-bytevector (quotient (string-length hex) 2))))
    (do ((i 0 (+ i 1))) ((= i (bytevector-length bv)) bv)
      (bytevector-u8-set! bv i (string->number (substring hex (* 2 i) (+ 2 (* 2 i))) 16)))))
(define (text s) (string->utf8 s))

(test-begin "hmac-sha256 (RFC 4231)")
(test "case 1"
    "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7"
  (hmac-sha256 (repeat #x0b 20) (text "Hi There")))
(test "case 2: key shorter than the block"
    "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"
  (hmac-sha256 (text "Jefe") (text "what do ya want for nothing?")))
(test "case 3"
    "773ea91e36800e46854db8ebd09181a72959098b3ef8c122d9635514ced565fe"
  (hmac-sha256 (repeat #xaa 20) (repeat #xdd 50)))
(test "case 4"
    "82558a389a443c0ea4cc819899f2083a85f0faa3e578f8077a2e3ff46729665b"
  (hmac-sha256 (hex->bytevector "0102030405060708090a0b0c0d0e0f10111213141516171819")
               (repeat #xcd 50)))
(test "case 5: truncation is the caller's; the first 128 bits match"
    "a3b6167473100ee06e0c796c2955552b"
  (substring (hmac-sha256 (repeat #x0c 20) (text "Test With Truncation")) 0 32))
(test "case 6: key longer than the block"
    "60e431591ee0b67f0d8a26aacbf5b77f8e0bc6213728c5140546040f0ee37f54"
  (hmac-sha256 (repeat #xaa 131)
               (text "Test Using Larger Than Block-Size Key - Hash Key First")))
(test "case 7: long key and long data"
    "9b09ffa71b942fcb27635fbcd5b0e944bfdc63644f0713938a7f51535c3a35e2"
  (hmac-sha256 (repeat #xaa 131)
               (text "This is a test using a larger than block-size key and a larger than block-size data. The key needs to be hashed before being used by the HMAC algorithm.")))
(test "a string message is its UTF-8 bytes"
    "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"
  (hmac-sha256 (text "Jefe") "what do ya want for nothing?"))
(test "a non-ASCII message as a string hashes its UTF-8 bytes"
  (hmac-sha256 (text "Jefe") (text "caf\xe9;"))
  (hmac-sha256 (text "Jefe") "caf\xe9;"))
(test "the parts of a message are hashed one after the other"
    "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"
  (hmac-sha256 (text "Jefe") "what do " (text "ya want") " for nothing?"))
(test "a fixnum part stands for its decimal digits"
  (hmac-sha256 (text "Jefe") "nonce:1234567:-5")
  (hmac-sha256 (text "Jefe") "nonce:" 1234567 ":" -5))
(test-error "a part that is neither bytes, text nor a fixnum"
  (hmac-sha256 (text "Jefe") 'what))

;; Signed texts, as frames carry them: the MAC, then the text.
(define key (text "Jefe"))
(define (signed t . parts) (string->utf8 (apply hmac-sha256-sign key t parts)))
(define (open-all bytes . parts)
  (apply hmac-sha256-open key bytes (bytevector-length bytes) parts))
(test "a signature is the MAC of the parts and the text, then the text"
  (string-append (hmac-sha256 key "n:" 7 ":" "(hello)") "(hello)")
  (hmac-sha256-sign key "(hello)" "n:" 7 ":"))
(test "a signed text opens with the same parts" "(hello)"
  (open-all (signed "(hello)" "n:" 7 ":") "n:" 7 ":"))
(test "a non-ASCII text opens as it was" "caf\xe9;"
  (open-all (signed "caf\xe9;" "n:") "n:"))
(test "not with other parts" #f
  (open-all (signed "(hello)" "n:" 7 ":") "n:" 8 ":"))
(test "not with a byte of the text changed" #f
  (let ((b (signed "(hello)" "n:")))
    (bytevector-u8-set! b 65 (char->integer #\j))
    (open-all b "n:")))
(test "not under another key" #f
  (hmac-sha256-open (text "other") (signed "(hello)") 71))
(test "fewer than 64 bytes do not open" #f
  (hmac-sha256-open key (bytevector 1 2 3) 3))
(test "only the first end bytes are the message" "(hello)"
  (let ((b (signed "(hello)")))
    (hmac-sha256-open key (bytevector-append b (bytevector 0 0))
                      (bytevector-length b))))
(test-error "an end past the bytes"
  (hmac-sha256-open key (signed "(hello)") 100))
(test-end)
(test-exit)
